//! The library's version at run time. The header's version macros (`TISSUESIM_VERSION_MAJOR`,
//! `_MINOR`, `_PATCH`, `TISSUESIM_VERSION`, `TISSUESIM_VERSION_STRING`) are written in
//! `cbindgen.toml` (cbindgen cannot render string constants); `tests/version.rs` checks that
//! they, [`ts_version`] and [`ts_version_string`] all agree with Cargo.toml.

use std::ffi::c_char;

/// Parse a decimal number at compile time.
const fn parse_u32(s: &str) -> u32 {
    let b = s.as_bytes();
    let mut i = 0;
    let mut v = 0u32;
    assert!(!b.is_empty(), "empty version component");
    while i < b.len() {
        assert!(b[i].is_ascii_digit(), "non-digit in version component");
        v = v * 10 + (b[i] - b'0') as u32;
        i += 1;
    }
    v
}

/// Major version (from Cargo.toml).
pub(crate) const MAJOR: u32 = parse_u32(env!("CARGO_PKG_VERSION_MAJOR"));
/// Minor version (from Cargo.toml).
pub(crate) const MINOR: u32 = parse_u32(env!("CARGO_PKG_VERSION_MINOR"));
/// Patch version (from Cargo.toml).
pub(crate) const PATCH: u32 = parse_u32(env!("CARGO_PKG_VERSION_PATCH"));

// MAJOR * 10000 + MINOR * 100 + PATCH is only unambiguous with two-digit minor and patch.
const _: () = assert!(MINOR < 100 && PATCH < 100);

/// The library's version at run time as MAJOR * 10000 + MINOR * 100 + PATCH (0.1.0 gives 100).
/// Compare with TISSUESIM_VERSION to detect a header/library mismatch.
#[no_mangle]
pub extern "C" fn ts_version() -> u32 {
    MAJOR * 10000 + MINOR * 100 + PATCH
}

/// The library's version at run time as a static NUL-terminated string "MAJOR.MINOR.PATCH".
/// Never NULL.
#[no_mangle]
pub extern "C" fn ts_version_string() -> *const c_char {
    concat!(env!("CARGO_PKG_VERSION"), "\0").as_ptr().cast()
}
