//! What carries a world's elasticity and what its volume constraints keep, from C (the Rust
//! `Settings::elastic_scheme` and `Settings::volume_scheme`). They are not fields of
//! ts_settings, whose layout is fixed: a world starts with the defaults, ts_world_set_schemes
//! changes them, and ts_world_set_settings keeps them.

use crate::ffi::args::world_mut;
use crate::ffi::error::{fail, FfiResult};
use crate::ffi::guard::guard;
use crate::ffi::status::ts_status;
use crate::ffi::world::{ts_world, world_value};
use crate::{ElasticScheme, Settings, VolumeScheme};

/// What carries the elasticity.
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ts_elastic_scheme {
    /// Corotated linear tetrahedra of the mesh (the default).
    Tetrahedra = 0,
    /// The paper's point-based particles (moving-least-squares deformation gradients): about
    /// 0.75x the default's step cost, too soft on coarse meshes, locking near nu 0.5 with
    /// per-tetrahedron volume constraints.
    PointBased = 1,
}

/// What one volume constraint keeps.
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ts_volume_scheme {
    /// A particle's dual cell, about one constraint per particle (the default): does not lock
    /// as nu -> 0.5.
    DualCells = 0,
    /// A tetrahedron, about six constraints per particle (the paper's): locks like linear
    /// tetrahedra as nu -> 0.5.
    Tetrahedra = 1,
}

/// A world's schemes: a ts_elastic_scheme and a ts_volume_scheme value.
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct ts_schemes {
    /// What carries the elasticity: a ts_elastic_scheme value.
    pub elastic: u32,
    /// What one volume constraint keeps: a ts_volume_scheme value.
    pub volume: u32,
}

fn elastic_scheme(value: u32) -> FfiResult<ElasticScheme> {
    match value {
        0 => Ok(ElasticScheme::Tetrahedra),
        1 => Ok(ElasticScheme::PointBased),
        v => Err(fail(
            ts_status::InvalidArgument,
            format!("elastic: {v} is not a ts_elastic_scheme"),
        )),
    }
}

fn volume_scheme(value: u32) -> FfiResult<VolumeScheme> {
    match value {
        0 => Ok(VolumeScheme::DualCells),
        1 => Ok(VolumeScheme::Tetrahedra),
        v => Err(fail(
            ts_status::InvalidArgument,
            format!("volume: {v} is not a ts_volume_scheme"),
        )),
    }
}

/// Select what carries the elasticity (`elastic`, a ts_elastic_scheme value) and what each
/// volume constraint keeps (`volume`, a ts_volume_scheme value) for every body of the world,
/// from the next step on; TS_ELASTIC_SCHEME_POINT_BASED with TS_VOLUME_SCHEME_TETRAHEDRA is the
/// paper's method. The bodies re-derive their stability limit and mass scaling, as a change of
/// settings does. A value that is not of its enum returns TS_STATUS_INVALID_ARGUMENT and
/// changes nothing.
///
/// # Safety
///
/// `world` is NULL or a live handle.
#[no_mangle]
pub unsafe extern "C" fn ts_world_set_schemes(
    world: *mut ts_world,
    elastic: u32,
    volume: u32,
) -> ts_status {
    guard(|| {
        let (elastic_scheme, volume_scheme) = (elastic_scheme(elastic)?, volume_scheme(volume)?);
        // SAFETY: contract of this function.
        let h = unsafe { world_mut(world)? };
        h.mutate(|w| {
            w.set_settings(Settings {
                elastic_scheme,
                volume_scheme,
                ..w.settings().clone()
            })
        })
    })
}

/// Write the world's schemes into *out_schemes (the defaults until ts_world_set_schemes).
///
/// # Safety
///
/// `world` is NULL or a live handle; `out_schemes` is NULL or writable.
#[no_mangle]
pub unsafe extern "C" fn ts_world_schemes(
    world: *const ts_world,
    out_schemes: *mut ts_schemes,
) -> ts_status {
    // SAFETY: contract of this function.
    unsafe {
        world_value(world, out_schemes, "out_schemes", |w| ts_schemes {
            elastic: match w.settings().elastic_scheme {
                ElasticScheme::Tetrahedra => ts_elastic_scheme::Tetrahedra as u32,
                ElasticScheme::PointBased => ts_elastic_scheme::PointBased as u32,
            },
            volume: match w.settings().volume_scheme {
                VolumeScheme::DualCells => ts_volume_scheme::DualCells as u32,
                VolumeScheme::Tetrahedra => ts_volume_scheme::Tetrahedra as u32,
            },
        })
    }
}
