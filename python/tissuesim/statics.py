"""Linear static solutions (the Rust ``tissuesim::statics`` module): small-strain
displacements (m) from the rest state, in the mesh's node order, and ``World.settle``'s
constants."""

from ._tissuesim import (
    SETTLE_MAX_ITERATIONS,
    SETTLE_MAX_STEPS,
    SETTLE_SPEED,
    SETTLE_TOLERANCE,
)
from ._tissuesim import statics_linear_gravity_sag as linear_gravity_sag
from ._tissuesim import statics_linear_response as linear_response

__all__ = [
    "SETTLE_MAX_ITERATIONS",
    "SETTLE_MAX_STEPS",
    "SETTLE_SPEED",
    "SETTLE_TOLERANCE",
    "linear_gravity_sag",
    "linear_response",
]
