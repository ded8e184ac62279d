//! The header's version macros, `ts_version()` and `ts_version_string()` agree with the crate
//! version in Cargo.toml.

use std::ffi::CStr;
use tissuesim::ffi::version::{ts_version, ts_version_string};

fn cargo_version() -> (u32, u32, u32) {
    let v: Vec<u32> = env!("CARGO_PKG_VERSION")
        .split(['.', '-', '+'])
        .take(3)
        .map(|p| p.parse().expect("numeric version component"))
        .collect();
    (v[0], v[1], v[2])
}

/// The value of `#define name value` in the committed header.
fn header_macro(name: &str) -> String {
    let path = concat!(env!("CARGO_MANIFEST_DIR"), "/include/tissuesim.h");
    let header = std::fs::read_to_string(path).expect("include/tissuesim.h exists");
    let prefix = format!("#define {name} ");
    header
        .lines()
        .find_map(|l| l.strip_prefix(&prefix))
        .unwrap_or_else(|| panic!("{name} is not defined in {path}"))
        .trim()
        .to_string()
}

#[test]
fn header_macros_match_cargo_version() {
    let (major, minor, patch) = cargo_version();
    let hint = "edit the version macros in cbindgen.toml, then run scripts/gen_header.sh";
    assert_eq!(
        header_macro("TISSUESIM_VERSION_MAJOR"),
        major.to_string(),
        "{hint}"
    );
    assert_eq!(
        header_macro("TISSUESIM_VERSION_MINOR"),
        minor.to_string(),
        "{hint}"
    );
    assert_eq!(
        header_macro("TISSUESIM_VERSION_PATCH"),
        patch.to_string(),
        "{hint}"
    );
    assert_eq!(
        header_macro("TISSUESIM_VERSION"),
        (major * 10000 + minor * 100 + patch).to_string(),
        "{hint}"
    );
    assert_eq!(
        header_macro("TISSUESIM_VERSION_STRING"),
        format!("\"{}\"", env!("CARGO_PKG_VERSION")),
        "{hint}"
    );
}

#[test]
fn run_time_version_matches_cargo_version() {
    let (major, minor, patch) = cargo_version();
    assert_eq!(ts_version(), major * 10000 + minor * 100 + patch);
    // SAFETY: ts_version_string returns a static NUL-terminated string.
    let s = unsafe { CStr::from_ptr(ts_version_string()) };
    assert_eq!(s.to_str().unwrap(), env!("CARGO_PKG_VERSION"));
}

#[test]
fn run_time_version_matches_header() {
    assert_eq!(header_macro("TISSUESIM_VERSION"), ts_version().to_string());
    // SAFETY: as above.
    let s = unsafe { CStr::from_ptr(ts_version_string()) };
    assert_eq!(
        header_macro("TISSUESIM_VERSION_STRING"),
        format!("\"{}\"", s.to_str().unwrap())
    );
}
