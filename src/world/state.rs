//! The world's dynamic state as a value: [`World::state`], [`World::state_into`] and
//! [`World::set_state`], on the world's scene ([`WorldState`] and the code behind these are in
//! `crate::scene::state`, which the step's rollback uses too).

use super::World;
use crate::error::Error;
use crate::scene::WorldState;

impl World {
    /// The world's dynamic state as a value (see [`WorldState`]).
    pub fn state(&self) -> WorldState {
        let mut out = WorldState::default();
        self.state_into(&mut out);
        out
    }

    /// Copy the world's dynamic state into `out`, reusing its memory: once `out` has held a
    /// state of this world, this allocates nothing.
    pub fn state_into(&self, out: &mut WorldState) {
        self.scene.state_into(out, self.pipeline.pool());
    }

    /// Put the world in `state`, taken from this world or from one built the same way. On any
    /// mismatch (body, tool or particle counts, non-finite values, a particle farther than
    /// [`STATE_POSITION_LIMIT`](crate::STATE_POSITION_LIMIT) body sizes from its body's rest
    /// centre or faster than [`STATE_SPEED_LIMIT`](crate::STATE_SPEED_LIMIT) body sizes per
    /// second, a grasp or needle hold of an unknown particle, a cut outside the body) the world
    /// is left unchanged and [`Error::BadState`] says why.
    pub fn set_state(&mut self, state: &WorldState) -> Result<(), Error> {
        self.scene.set_state(state)?;
        self.pipeline.fit_boundaries(&self.scene.bodies);
        Ok(())
    }
}
