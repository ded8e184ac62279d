//! The world's state as bytes: [`World::save_state`], [`World::restore_state`] and the size
//! of what they write, in the format of [`crate::state`] (the saved-state byte format).

use super::World;
use crate::error::Error;
use crate::scene::WorldState;
use crate::world::state_bytes::layout_size;

impl World {
    /// Size in bytes of the state [`World::save_state`] writes now (computed from the world,
    /// without taking its state).
    pub fn state_size(&self) -> usize {
        let bodies = self.scene.bodies.iter().map(|b| {
            let cuts = crate::scene::cut::cut_sets(b).map_or(0, |c| c.0.len() + c.1.len());
            (b.particle_count(), cuts)
        });
        let tools = (self.scene.tools.iter().flatten()).map(|s| {
            let holds = s.needle.as_ref().map_or(0, |n| n.holds.len());
            (s.grasp.attachments.len(), holds)
        });
        layout_size(bodies, tools)
    }

    /// Append the world's dynamic state ([`World::state`]) to `out` in the format of
    /// [`crate::state`].
    pub fn save_state(&self, out: &mut Vec<u8>) {
        out.reserve(self.state_size());
        self.state().to_bytes(out);
    }

    /// Restore a state written by [`World::save_state`] of a world built the same way:
    /// [`WorldState::from_bytes`] then [`World::set_state`]. On any error the world is left
    /// unchanged and [`Error::BadState`] says why.
    pub fn restore_state(&mut self, bytes: &[u8]) -> Result<(), Error> {
        self.set_state(&WorldState::from_bytes(bytes)?)
    }
}
