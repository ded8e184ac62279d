//! Package `TissueSim.fmu`: `modelDescription.xml` generated from the variable table, the
//! shared library under `binaries/<platform>/TissueSim.<ext>`, and `resources/organ.vtk` (the
//! default organ) plus `resources/scene.txt` (the default parameters).
//!
//! ```text
//! cargo run --release -p tissuesim-fmu --bin build-fmu -- [--out PATH] [--lib PATH] [--keep-debug]
//! cargo run -p tissuesim-fmu --bin build-fmu -- --docs-table          # print the docs table
//! cargo run -p tissuesim-fmu --bin build-fmu -- --update-docs docs/FMU.md
//! ```
//!
//! `--docs-table` prints the Markdown variables table generated from the variable table (the
//! one `modelDescription.xml` comes from); `--update-docs FILE` rewrites the table between the
//! markers of `tissuesim_fmu::fmi2::docs` in FILE. Neither builds anything.
//!
//! Unless `--lib` names a library, the program first runs `cargo build --release -p
//! tissuesim-fmu --lib` (with the `cargo` that started it, so `CARGO_TARGET_DIR` is honoured;
//! `cargo run` alone does not copy a cdylib to `target/release/`) and packages
//! `<target dir>/release/libTissueSim.so`. The archive is written with the `zip` crate
//! (deflated entries, fixed timestamps). The default output is
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
    docs_table: bool,
    update_docs: Option<PathBuf>,
}

fn parse_args() -> Result<Args, String> {
    let mut args = Args {
        out: None,
        lib: None,
        keep_debug: false,
        docs_table: false,
        update_docs: None,
    };
    let mut it = std::env::args().skip(1);
    while let Some(a) = it.next() {
        match a.as_str() {
            "--out" => args.out = Some(it.next().ok_or("--out needs a path")?.into()),
            "--lib" => args.lib = Some(it.next().ok_or("--lib needs a path")?.into()),
            "--keep-debug" => args.keep_debug = true,
            "--docs-table" => args.docs_table = true,
            "--update-docs" => {
                args.update_docs = Some(it.next().ok_or("--update-docs needs a path")?.into())
            }
            "-h" | "--help" => {
                println!(
                    "usage: build-fmu [--out PATH] [--lib PATH] [--keep-debug]\n\
                     \x20      build-fmu --docs-table | --update-docs FILE\n\
                     Writes TissueSim.fmu (default <target dir>/fmu/TissueSim.fmu), or prints\n\
                     the generated variables table, or rewrites it in FILE (docs/FMU.md)."
                );
                std::process::exit(0);
            }
            other => return Err(format!("unknown argument {other}")),
        }
    }
    Ok(args)
}

fn run() -> Result<Option<PathBuf>, String> {
    let args = parse_args()?;
    if args.docs_table {
        print!("{}", TissueSim::docs_table());
        return Ok(None);
    }
    if let Some(path) = args.update_docs {
        let text = fs::read_to_string(&path).map_err(|e| format!("{}: {e}", path.display()))?;
        let new = TissueSim::fmi2::docs::replace_table(&text, &TissueSim::docs_table())
            .map_err(|e| format!("{}: {e}", path.display()))?;
        if new != text {
            fs::write(&path, new).map_err(|e| format!("{}: {e}", path.display()))?;
            eprintln!(
                "build-fmu: updated the variables table of {}",
                path.display()
            );
        }
        return Ok(None);
    }
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
    let zip = archive(&files).map_err(|e| format!("zipping {}: {e}", out.display()))?;
    fs::write(&out, zip).map_err(|e| format!("writing {}: {e}", out.display()))?;
    let _ = fs::remove_dir_all(&staging);
    Ok(Some(out))
}

fn main() -> ExitCode {
    match run() {
        Ok(out) => {
            if let Some(out) = out {
                println!("{}", out.display());
            }
            ExitCode::SUCCESS
        }
        Err(e) => {
            eprintln!("build-fmu: {e}");
            ExitCode::FAILURE
        }
    }
}

/// The bytes of a ZIP archive holding `files` (name, content): deflated, with the fixed
/// timestamp 1980-01-01 00:00 (reproducible archives) and Unix modes (0755 for the shared
/// library, 0644 otherwise).
fn archive(files: &[(String, Vec<u8>)]) -> zip::result::ZipResult<Vec<u8>> {
    use std::io::Write;
    use zip::write::SimpleFileOptions;
    let mut zip = zip::ZipWriter::new(std::io::Cursor::new(Vec::new()));
    for (name, data) in files {
        let mode = if name.starts_with("binaries/") {
            0o755
        } else {
            0o644
        };
        let options = SimpleFileOptions::default()
            .compression_method(zip::CompressionMethod::Deflated)
            .last_modified_time(zip::DateTime::default())
            .unix_permissions(mode);
        zip.start_file(name.as_str(), options)?;
        zip.write_all(data)?;
    }
    Ok(zip.finish()?.into_inner())
}

#[cfg(test)]
mod tests {
    use std::io::Read;

    /// The archive reads back (names, contents, modes) and is byte-for-byte reproducible.
    #[test]
    fn archive_round_trip() {
        let files = vec![
            ("modelDescription.xml".to_string(), b"<xml/>".repeat(100)),
            ("binaries/linux64/M.so".to_string(), vec![0u8, 1, 2, 255]),
            ("resources/empty.txt".to_string(), Vec::new()),
        ];
        let bytes = super::archive(&files).unwrap();
        assert_eq!(bytes, super::archive(&files).unwrap());
        let mut zip = zip::ZipArchive::new(std::io::Cursor::new(bytes)).unwrap();
        assert_eq!(zip.len(), files.len());
        for (name, data) in &files {
            let mut f = zip.by_name(name).unwrap();
            let mut back = Vec::new();
            f.read_to_end(&mut back).unwrap();
            assert_eq!(&back, data);
            let mode = f.unix_mode().unwrap() & 0o777;
            assert_eq!(mode, if name.ends_with(".so") { 0o755 } else { 0o644 });
        }
    }
}
