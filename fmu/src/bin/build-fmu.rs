//! Package `TissueSim.fmu`: `modelDescription.xml` generated from the variable table, the
//! shared library under `binaries/<platform>/TissueSim.<ext>`, and `resources/organ.vtk` (the
//! default organ) plus `resources/scene.txt` (the default parameters).
//!
//! ```text
//! cargo run --release -p tissuesim-fmu --bin build-fmu -- [--out PATH] [--lib PATH] [--keep-debug]
//! ```
//!
//! Unless `--lib` names a library, the program first runs `cargo build --release -p
//! tissuesim-fmu --lib` (with the `cargo` that started it, so `CARGO_TARGET_DIR` is honoured;
//! `cargo run` alone does not copy a cdylib to `target/release/`) and packages
//! `<target dir>/release/libTissueSim.so`. The default output is
//! `<target dir>/fmu/TissueSim.fmu`. Debug info is stripped from the packaged copy with
//! `strip --strip-debug` when that tool exists (`--keep-debug` keeps it).

use std::fs;
use std::path::PathBuf;
use std::process::{Command, ExitCode};
use TissueSim::model::scene_text;

fn platform() -> (&'static str, &'static str, &'static str) {
    // (FMI platform folder, library prefix in target/, extension)
    if cfg!(target_os = "windows") {
        ("win64", "", "dll")
    } else if cfg!(target_os = "macos") {
        ("darwin64", "lib", "dylib")
    } else if cfg!(target_pointer_width = "32") {
        ("linux32", "lib", "so")
    } else {
        ("linux64", "lib", "so")
    }
}

struct Args {
    out: Option<PathBuf>,
    lib: Option<PathBuf>,
    keep_debug: bool,
}

fn parse_args() -> Result<Args, String> {
    let mut args = Args {
        out: None,
        lib: None,
        keep_debug: false,
    };
    let mut it = std::env::args().skip(1);
    while let Some(a) = it.next() {
        match a.as_str() {
            "--out" => args.out = Some(it.next().ok_or("--out needs a path")?.into()),
            "--lib" => args.lib = Some(it.next().ok_or("--lib needs a path")?.into()),
            "--keep-debug" => args.keep_debug = true,
            "-h" | "--help" => {
                println!(
                    "usage: build-fmu [--out PATH] [--lib PATH] [--keep-debug]\n\
                     Writes TissueSim.fmu (default <target dir>/fmu/TissueSim.fmu)."
                );
                std::process::exit(0);
            }
            other => return Err(format!("unknown argument {other}")),
        }
    }
    Ok(args)
}

fn run() -> Result<PathBuf, String> {
    let args = parse_args()?;
    let exe = std::env::current_exe().map_err(|e| e.to_string())?;
    let exe_dir = exe.parent().ok_or("no executable directory")?.to_path_buf();
    // The program lives in <target dir>/<profile>/.
    let target_dir = exe_dir.parent().unwrap_or(&exe_dir).to_path_buf();
    let (plat, prefix, ext) = platform();
    let lib = match args.lib {
        Some(lib) => lib,
        None => {
            let cargo = std::env::var_os("CARGO").unwrap_or_else(|| "cargo".into());
            let status = Command::new(&cargo)
                .args(["build", "--release", "-p", "tissuesim-fmu", "--lib"])
                .env("CARGO_TARGET_DIR", &target_dir)
                .status()
                .map_err(|e| format!("cannot run {cargo:?}: {e}"))?;
            if !status.success() {
                return Err("cargo build --release -p tissuesim-fmu --lib failed".into());
            }
            target_dir
                .join("release")
                .join(format!("{prefix}TissueSim.{ext}"))
        }
    };
    let lib_bytes = fs::read(&lib).map_err(|e| {
        format!(
            "cannot read the shared library {}: {e} (build it with `cargo build --release -p tissuesim-fmu`)",
            lib.display()
        )
    })?;
    let out = args
        .out
        .unwrap_or_else(|| target_dir.join("fmu").join("TissueSim.fmu"));
    let staging = out.with_extension("fmu.d");
    let _ = fs::remove_dir_all(&staging);
    fs::create_dir_all(staging.join("resources")).map_err(|e| e.to_string())?;

    // The library, stripped of debug info when possible.
    let lib_copy = staging.join(format!("TissueSim.{ext}"));
    fs::write(&lib_copy, &lib_bytes).map_err(|e| e.to_string())?;
    if !args.keep_debug && ext == "so" {
        match Command::new("strip")
            .arg("--strip-debug")
            .arg(&lib_copy)
            .status()
        {
            Ok(s) if s.success() => {}
            _ => eprintln!("build-fmu: `strip` unavailable or failed; packaging with debug info"),
        }
    }
    let lib_bytes = fs::read(&lib_copy).map_err(|e| e.to_string())?;

    let organ_path = staging.join("resources").join("organ.vtk");
    tissuesim::mesh::write_vtk(&organ_path, &tissuesim::mesh::default_organ())
        .map_err(|e| format!("writing {}: {e}", organ_path.display()))?;
    let organ = fs::read(&organ_path).map_err(|e| e.to_string())?;

    let files: Vec<(String, Vec<u8>)> = vec![
        (
            "modelDescription.xml".into(),
            TissueSim::model_description().into_bytes(),
        ),
        (format!("binaries/{plat}/TissueSim.{ext}"), lib_bytes),
        ("resources/organ.vtk".into(), organ),
        ("resources/scene.txt".into(), scene_text().into_bytes()),
    ];
    if let Some(dir) = out.parent() {
        fs::create_dir_all(dir).map_err(|e| e.to_string())?;
    }
    let zip = zip::store(&files);
    fs::write(&out, zip).map_err(|e| format!("writing {}: {e}", out.display()))?;
    let _ = fs::remove_dir_all(&staging);
    Ok(out)
}

fn main() -> ExitCode {
    match run() {
        Ok(out) => {
            println!("{}", out.display());
            ExitCode::SUCCESS
        }
        Err(e) => {
            eprintln!("build-fmu: {e}");
            ExitCode::FAILURE
        }
    }
}

/// A minimal ZIP writer: stored (uncompressed) entries, fixed timestamps (reproducible).
mod zip {
    fn crc32(data: &[u8]) -> u32 {
        let mut table = [0u32; 256];
        for (i, t) in table.iter_mut().enumerate() {
            let mut c = i as u32;
            for _ in 0..8 {
                c = if c & 1 != 0 {
                    0xEDB8_8320 ^ (c >> 1)
                } else {
                    c >> 1
                };
            }
            *t = c;
        }
        !data.iter().fold(!0u32, |c, &b| {
            table[((c ^ b as u32) & 0xff) as usize] ^ (c >> 8)
        })
    }

    fn u16le(v: &mut Vec<u8>, x: u16) {
        v.extend_from_slice(&x.to_le_bytes());
    }
    fn u32le(v: &mut Vec<u8>, x: u32) {
        v.extend_from_slice(&x.to_le_bytes());
    }

    /// The bytes of a ZIP archive holding `files` (name, content), stored.
    pub fn store(files: &[(String, Vec<u8>)]) -> Vec<u8> {
        const DOS_TIME: u16 = 0;
        const DOS_DATE: u16 = (1 << 5) | 1; // 1980-01-01
        let mut out = Vec::new();
        let mut central = Vec::new();
        for (name, data) in files {
            let crc = crc32(data);
            let offset = out.len() as u32;
            let size = data.len() as u32;
            u32le(&mut out, 0x0403_4b50);
            u16le(&mut out, 20); // version needed
            u16le(&mut out, 0x0800); // flags: UTF-8 names
            u16le(&mut out, 0); // stored
            u16le(&mut out, DOS_TIME);
            u16le(&mut out, DOS_DATE);
            u32le(&mut out, crc);
            u32le(&mut out, size);
            u32le(&mut out, size);
            u16le(&mut out, name.len() as u16);
            u16le(&mut out, 0);
            out.extend_from_slice(name.as_bytes());
            out.extend_from_slice(data);

            u32le(&mut central, 0x0201_4b50);
            u16le(&mut central, (3 << 8) | 20); // made by: Unix, 2.0
            u16le(&mut central, 20);
            u16le(&mut central, 0x0800);
            u16le(&mut central, 0);
            u16le(&mut central, DOS_TIME);
            u16le(&mut central, DOS_DATE);
            u32le(&mut central, crc);
            u32le(&mut central, size);
            u32le(&mut central, size);
            u16le(&mut central, name.len() as u16);
            u16le(&mut central, 0); // extra
            u16le(&mut central, 0); // comment
            u16le(&mut central, 0); // disk
            u16le(&mut central, 0); // internal attributes
            let mode: u32 = if name.ends_with(".so") {
                0o100755
            } else {
                0o100644
            };
            u32le(&mut central, mode << 16);
            u32le(&mut central, offset);
            central.extend_from_slice(name.as_bytes());
        }
        let cd_offset = out.len() as u32;
        let cd_size = central.len() as u32;
        out.extend_from_slice(&central);
        u32le(&mut out, 0x0605_4b50);
        u16le(&mut out, 0);
        u16le(&mut out, 0);
        u16le(&mut out, files.len() as u16);
        u16le(&mut out, files.len() as u16);
        u32le(&mut out, cd_size);
        u32le(&mut out, cd_offset);
        u16le(&mut out, 0);
        out
    }

    #[cfg(test)]
    mod tests {
        #[test]
        fn crc_of_known_string() {
            assert_eq!(super::crc32(b"123456789"), 0xCBF4_3926);
        }
    }
}
