//! The organ models of the live instances in this process, shared between instances built from
//! the same mesh and options.
//!
//! A master that runs several instances of the FMU (a parameter sweep, a bank of trainers)
//! would otherwise rebuild and hold the same neighbourhoods and consistent gradients once per
//! instance: the costly part of `fmi2ExitInitializationMode` and most of an instance's memory.
//! The registry keeps only weak references, so a model lives as long as an instance uses it.
//! Instances still own their state: the model is immutable, and a cut gives the cut instance
//! its own copy (copy-on-write in the core).

use std::sync::{Arc, Mutex, PoisonError, Weak};
use tissuesim::mesh::TetMesh;
use tissuesim::{BodyModel, BodyOptions, Error};

/// Weak references to the models built so far in this process.
static MODELS: Mutex<Vec<Weak<BodyModel>>> = Mutex::new(Vec::new());

/// The model of `mesh` with `options`: one a live instance already holds when its options,
/// rest positions and tetrahedra are equal (bit for bit), else a new one, registered.
pub fn shared_model(mesh: &TetMesh, options: &BodyOptions) -> Result<Arc<BodyModel>, Error> {
    // The registry only holds weak references: a panic elsewhere cannot leave it inconsistent.
    let mut models = MODELS.lock().unwrap_or_else(PoisonError::into_inner);
    models.retain(|m| m.strong_count() > 0);
    let same = |m: &Arc<BodyModel>| m.is_built_from(mesh, options);
    if let Some(model) = models.iter().filter_map(Weak::upgrade).find(same) {
        return Ok(model);
    }
    let model = BodyModel::new(mesh, options)?;
    models.push(Arc::downgrade(&model));
    Ok(model)
}

#[cfg(test)]
mod tests {
    use super::*;
    use tissuesim::mesh::lattice_box;
    use tissuesim::{Material, Vec3};

    fn block(cells: usize) -> TetMesh {
        lattice_box(Vec3::zeros(), Vec3::new(0.04, 0.02, 0.02), [cells, 2, 2])
    }

    #[test]
    fn equal_meshes_and_options_share_one_model_while_it_lives() {
        let options = BodyOptions::default();
        let a = shared_model(&block(4), &options).unwrap();
        let b = shared_model(&block(4), &options).unwrap();
        assert!(Arc::ptr_eq(&a, &b));
        // Another mesh or other options get their own.
        let other_mesh = shared_model(&block(5), &options).unwrap();
        assert!(!Arc::ptr_eq(&a, &other_mesh));
        let stiffer = BodyOptions {
            material: Material {
                youngs_modulus: 2.0 * options.material.youngs_modulus,
                ..options.material
            },
            ..options.clone()
        };
        let c = shared_model(&block(4), &stiffer).unwrap();
        assert!(!Arc::ptr_eq(&a, &c));
        // Once no instance holds it, the next request builds a new one.
        let weak = Arc::downgrade(&a);
        drop((a, b));
        assert_eq!(weak.strong_count(), 0);
        let d = shared_model(&block(4), &options).unwrap();
        assert_eq!(d.particle_count(), block(4).nodes.len());
    }
}
