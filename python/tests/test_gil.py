"""The GIL is released during long calls: another Python thread makes progress meanwhile."""

from __future__ import annotations

import threading
import time

import tissuesim as ts
from tissuesim.scenarios import Scene


class Counter(threading.Thread):
    """Counts in pure Python until stopped: it can only count while it holds the GIL."""

    def __init__(self) -> None:
        super().__init__(daemon=True)
        self.count = 0
        self.stop = False

    def run(self) -> None:
        while not self.stop:
            self.count += 1


def counted_during(call) -> tuple[int, float]:
    counter = Counter()
    counter.start()
    time.sleep(0.05)
    start, t0 = counter.count, time.perf_counter()
    call()
    elapsed = time.perf_counter() - t0
    counted = counter.count - start
    counter.stop = True
    counter.join()
    return counted, elapsed


def test_another_thread_runs_during_settle():
    scene = Scene(settle=False)
    # Without the GIL released, the counter would get only the interpreter's switch
    # interval's worth of turns (5 ms each) at the call's start and end.
    counted, elapsed = counted_during(scene.world.settle)
    assert elapsed > 0.5
    assert counted > 100_000, f"{counted} counts in {elapsed:.2f} s"


def test_another_thread_runs_during_steps():
    scene = Scene(settle=False)

    def steps() -> None:
        for _ in range(500):
            scene.world.step()

    counted, elapsed = counted_during(steps)
    assert counted > 50_000, f"{counted} counts in {elapsed:.2f} s"


def test_a_second_thread_calling_the_same_world_during_a_step_gets_an_error_not_a_race():
    scene = Scene(settle=False)
    errors: list[BaseException] = []
    done = threading.Event()

    def poke() -> None:
        while not done.is_set():
            try:
                scene.world.time()
            except RuntimeError as e:  # already borrowed while the step runs
                errors.append(e)

    thread = threading.Thread(target=poke)
    thread.start()
    for _ in range(300):
        scene.world.step()
    done.set()
    thread.join()
    assert errors, "the world is borrowed during a step"
    assert all("borrow" in str(e) for e in errors)
    assert abs(scene.world.time() - 0.3) < 1e-9
    assert isinstance(scene.world, ts.World)
