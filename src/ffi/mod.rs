//! The C ABI of tissuesim: handles, status codes, the panic guard and the thread's last error.
//! No physics lives here; every function maps C arguments onto the Rust API of the crate.
//!
//! Conventions (after rustls-ffi and MuJoCo), also stated at the top of `include/tissuesim.h`:
//!
//! - every symbol starts with `ts_` (types and functions) or `TS_` / `TISSUESIM_` (constants);
//! - a world is an opaque handle ([`world::ts_world`]) made by `ts_world_new` and released by
//!   `ts_world_free`; bodies and tools inside it are addressed by `uint32_t` ids;
//! - every fallible call returns a [`status::ts_status`]; outputs are written only when it is
//!   `TS_STATUS_OK`; on failure the thread's last error message says why
//!   (`ts_last_error_message`);
//! - NULL pointer arguments give `TS_STATUS_NULL_PARAMETER` unless documented as optional;
//!   NaN/Inf inputs give `TS_STATUS_NON_FINITE` and leave the world untouched;
//! - every export runs behind [`guard::guard`]: a Rust panic never unwinds into C, it becomes
//!   `TS_STATUS_PANIC`, and a world whose mutation panicked is poisoned
//!   (`TS_STATUS_POISONED` from then on, only `ts_world_free` still works on it);
//! - arrays are `(pointer, length)` pairs; output arrays are caller buffers whose length is
//!   given in elements of the pointed-to type (doubles, `uint32_t`s or bytes);
//! - particle `k` of a body is node `k` of its mesh (after unreferenced nodes are removed,
//!   `ts_body_source_indices`): every per-particle array and index reads and writes in the
//!   mesh's node order, whatever order the solver keeps internally.
//!
//! Thread rules: a world may be used by one thread at a time (it may move between threads);
//! different worlds are independent and may be stepped concurrently. The last error message
//! is per thread.
//!
//! The header is generated from this module tree only (`cbindgen.toml`, see
//! `tests/header_drift.rs`), so nothing outside `src/ffi` reaches it.
#![allow(non_camel_case_types)]

// Declaration order = order of the declarations in the generated header (kept apart by blank
// lines so that rustfmt does not sort them).
pub mod version;

pub mod status;

pub mod error;

pub mod guard;

pub mod args;

pub mod world;

pub mod body;

pub mod tool;

pub mod grasp;

pub mod needle;

pub mod cut;

pub mod state;

pub mod render;

pub mod profile;

pub mod scheme;

pub mod crushed_substeps;

pub use body::{ts_body_options, ts_material};
pub use cut::ts_cut_report;
pub use grasp::ts_grasp_options;
pub use needle::{ts_needle_options, ts_needle_state};
pub use profile::ts_step_profile;
pub use scheme::{ts_elastic_scheme, ts_schemes, ts_volume_scheme};
pub use status::ts_status;
pub use tool::{ts_pose, ts_tool_options, ts_wrench};
pub use world::{ts_contact_mode, ts_settings, ts_step_report, ts_world};
