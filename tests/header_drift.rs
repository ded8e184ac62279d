//! The committed `include/tissuesim.h` must be exactly what cbindgen (pinned 0.29.4) generates
//! from `src/ffi` with `cbindgen.toml`. Regenerate with `scripts/gen_header.sh`, which runs
//! `cargo test -p tissuesim --test header_drift -- --ignored regenerate`.

use std::path::{Path, PathBuf};

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

fn header_path() -> PathBuf {
    root().join("include").join("tissuesim.h")
}

/// The header as cbindgen generates it now.
fn generate() -> String {
    let root = root();
    let config =
        cbindgen::Config::from_file(root.join("cbindgen.toml")).expect("cbindgen.toml must parse");
    let bindings = cbindgen::Builder::new()
        .with_config(config)
        .with_src(root.join("src").join("ffi").join("mod.rs"))
        .generate()
        .expect("cbindgen must generate the header from src/ffi");
    let mut out = Vec::new();
    bindings.write(&mut out);
    String::from_utf8(out).expect("the header is UTF-8")
}

fn first_difference(a: &str, b: &str) -> Option<(usize, String, String)> {
    let (mut la, mut lb) = (a.lines(), b.lines());
    let mut n = 0;
    loop {
        n += 1;
        match (la.next(), lb.next()) {
            (None, None) => return None,
            (x, y) if x == y => continue,
            (x, y) => {
                return Some((
                    n,
                    x.unwrap_or("<end of file>").to_string(),
                    y.unwrap_or("<end of file>").to_string(),
                ))
            }
        }
    }
}

#[test]
fn committed_header_matches_generated() {
    let fresh = generate();
    let path = header_path();
    let committed = std::fs::read_to_string(&path).unwrap_or_default();
    if committed != fresh {
        let hint = match first_difference(&committed, &fresh) {
            Some((line, old, new)) => {
                format!("first difference at line {line}:\n  committed: {old}\n  generated: {new}")
            }
            None => "the files differ only in trailing newlines".to_string(),
        };
        panic!(
            "{} is out of date with src/ffi + cbindgen.toml.\n{hint}\n\
             Regenerate it with:\n    scripts/gen_header.sh\n\
             (or: cargo test -p tissuesim --test header_drift -- --ignored regenerate)\n\
             then review `git diff include/tissuesim.h` and commit it.",
            path.display()
        );
    }
}

/// The header without its comments.
fn strip_comments(src: &str) -> String {
    let mut out = String::with_capacity(src.len());
    let mut rest = src;
    while !rest.is_empty() {
        if let Some(r) = rest.strip_prefix("/*") {
            rest = r.find("*/").map_or("", |i| &r[i + 2..]);
        } else if let Some(r) = rest.strip_prefix("//") {
            rest = r.find('\n').map_or("", |i| &r[i..]);
        } else {
            let c = rest.chars().next().unwrap();
            out.push(c);
            rest = &rest[c.len_utf8()..];
        }
    }
    out
}

/// Every name the header declares at file scope (macros, types, enumerators, functions).
fn declared_names(header: &str) -> Vec<String> {
    let code = strip_comments(header);
    let ident = |s: &str| -> String {
        s.trim_start_matches(|c: char| !(c.is_alphanumeric() || c == '_'))
            .chars()
            .take_while(|c| c.is_alphanumeric() || *c == '_')
            .collect()
    };
    let mut names = Vec::new();
    let mut depth = 0usize;
    let mut in_enum = false;
    for line in code.lines().map(str::trim) {
        if line.is_empty() || line.starts_with("#include") || line.starts_with("#if") {
            continue;
        }
        if line.starts_with("#endif") || line.starts_with("extern \"C\"") {
            continue;
        }
        if let Some(rest) = line.strip_prefix("#define ") {
            names.push(ident(rest));
            continue;
        }
        if depth == 0 && line.starts_with("typedef enum") {
            in_enum = true;
        }
        if depth == 1 && in_enum && line.contains('=') {
            names.push(ident(line));
        }
        if depth == 0 && line.contains('(') {
            let before = &line[..line.find('(').unwrap()];
            names.push(ident(before.rsplit([' ', '*']).next().unwrap_or("")));
        }
        if depth == 0 && line.starts_with("typedef") && line.ends_with(';') {
            names.push(ident(
                line.trim_end_matches(';').rsplit(' ').next().unwrap_or(""),
            ));
        }
        if line.starts_with('}') && line.ends_with(';') && depth == 1 {
            let name = ident(line.trim_start_matches('}'));
            if !name.is_empty() {
                names.push(name);
            }
            in_enum = false;
        }
        depth += line.matches('{').count();
        depth -= line.matches('}').count().min(depth);
    }
    names
}

/// Only tissuesim's own names reach the header: `ts_` types and functions, `TS_` enumerators and
/// `TISSUESIM_` macros; no FMI symbols, no Rust internals.
#[test]
fn header_declares_only_ts_names() {
    let names = declared_names(&generate());
    assert!(names.iter().any(|n| n == "ts_world_step"), "{names:?}");
    assert!(names.iter().any(|n| n == "TS_STATUS_OK"), "{names:?}");
    assert!(names.iter().any(|n| n == "ts_world"), "{names:?}");
    let bad: Vec<&String> = names
        .iter()
        .filter(|n| !(n.starts_with("ts_") || n.starts_with("TS_") || n.starts_with("TISSUESIM_")))
        .collect();
    assert!(bad.is_empty(), "non-tissuesim names in the header: {bad:?}");
    assert!(
        !generate().contains("fmi"),
        "FMI symbols must stay out of the header"
    );
}

/// Writes `include/tissuesim.h` from `src/ffi` and `cbindgen.toml`.
#[test]
#[ignore = "writes include/tissuesim.h; run explicitly to regenerate"]
fn regenerate() {
    let path = header_path();
    std::fs::create_dir_all(path.parent().unwrap_or(Path::new("."))).unwrap();
    std::fs::write(&path, generate()).unwrap();
    println!("wrote {}", path.display());
}
