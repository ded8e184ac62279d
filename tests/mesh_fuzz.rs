//! Seeded mutation fuzzing of the mesh readers, bounded in time: every mutated file either
//! loads or gives an error that names the file, never a panic; a mutated tetrahedral mesh that
//! loads either becomes a body or gives an error, never a panic. The seed is fixed, so a
//! failure reproduces; `TISSUESIM_FUZZ_CASES` raises the number of cases per seed file for a
//! longer local run.

mod common;

use std::panic::{catch_unwind, AssertUnwindSafe};
use std::path::{Path, PathBuf};
use tissuesim::mesh::{self, lattice_box};
use tissuesim::{BodyOptions, Settings, Vec3, World};

/// xorshift64*: small, seeded, good enough to pick mutations.
struct Rng(u64);

impl Rng {
    fn next(&mut self) -> u64 {
        self.0 ^= self.0 >> 12;
        self.0 ^= self.0 << 25;
        self.0 ^= self.0 >> 27;
        self.0.wrapping_mul(0x2545_f491_4f6c_dd1d)
    }
    fn below(&mut self, n: usize) -> usize {
        (self.next() % n.max(1) as u64) as usize
    }
}

/// Tokens a hostile or broken file may hold where a number is expected.
const TOKENS: &[&str] = &[
    "nan",
    "inf",
    "-inf",
    "1e400",
    "-1",
    "0",
    "4294967295",
    "18446744073709551616",
    "1e-320",
    "-0",
    "",
    "$EndElements",
    "CELLS",
    "f",
    "v",
    "#",
    "\u{0}",
    "é",
    "1/2/3",
    "  ",
    "\n",
];

/// One mutation of `text`: a byte flipped, a token inserted or swapped for a word, a line
/// deleted or duplicated, or the text cut.
fn mutate(text: &[u8], rng: &mut Rng) -> Vec<u8> {
    let mut out = text.to_vec();
    let at = rng.below(out.len());
    match rng.below(6) {
        0 => out[at] ^= 1 << rng.below(8),
        1 => {
            let token = TOKENS[rng.below(TOKENS.len())].as_bytes();
            out.splice(at..at, token.iter().copied());
        }
        2 => {
            // Replace the whitespace-delimited word at `at`.
            let start = out[..at]
                .iter()
                .rposition(|b| b.is_ascii_whitespace())
                .map_or(0, |k| k + 1);
            let end = out[at..]
                .iter()
                .position(|b| b.is_ascii_whitespace())
                .map_or(out.len(), |k| at + k);
            let token = TOKENS[rng.below(TOKENS.len())].as_bytes();
            out.splice(start..end, token.iter().copied());
        }
        3 | 4 => {
            let start = out[..at]
                .iter()
                .rposition(|&b| b == b'\n')
                .map_or(0, |k| k + 1);
            let end = out[at..]
                .iter()
                .position(|&b| b == b'\n')
                .map_or(out.len(), |k| at + k + 1);
            let line = out[start..end].to_vec();
            if rng.below(2) == 0 {
                out.drain(start..end);
            } else {
                out.splice(end..end, line);
            }
        }
        _ => out.truncate(at),
    }
    out
}

fn cases() -> usize {
    std::env::var("TISSUESIM_FUZZ_CASES")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(300)
}

/// A fresh directory for one test (tests run in parallel).
fn scratch(test: &str) -> PathBuf {
    let dir =
        std::env::temp_dir().join(format!("tissuesim-mesh-fuzz-{}-{test}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// Load `path` (a tetrahedral mesh, or an OBJ surface when `obj`), and when a tetrahedral mesh
/// loads, build a body from it. Panics only with a message describing the case.
fn load_never_panics(path: &Path, obj: bool, case: &str) {
    // A TetGen error may name the other file of the pair: the stem names both.
    let name = path.file_stem().unwrap().to_string_lossy().to_string();
    let outcome = catch_unwind(AssertUnwindSafe(|| {
        if obj {
            if let Err(e) = mesh::read_obj(path, 1.0) {
                assert!(
                    e.to_string().contains(&name),
                    "{case}: error without the file: {e}"
                );
            }
            return;
        }
        match mesh::load(path, 1.0) {
            Err(e) => assert!(
                e.to_string().contains(&name),
                "{case}: error without the file: {e}"
            ),
            Ok((m, _)) => {
                let mut w = World::new(Settings::default()).unwrap();
                // A mutated mesh may be degenerate: an error is fine, a panic is not.
                let _ = w.add_body(&m, &BodyOptions::default());
            }
        }
    }));
    if outcome.is_err() {
        panic!("{case}: the reader or the body builder panicked (file kept at {path:?})");
    }
}

fn fuzz(seed_name: &str, text: &[u8], obj: bool, rng: &mut Rng) {
    let dir = scratch(seed_name);
    let ext = Path::new(seed_name).extension().unwrap().to_str().unwrap();
    for k in 0..cases() {
        let mut bytes = mutate(text, rng);
        if rng.below(3) == 0 {
            bytes = mutate(&bytes, rng);
        }
        let path = dir.join(format!("fuzz.{ext}"));
        std::fs::write(&path, &bytes).unwrap();
        load_never_panics(&path, obj, &format!("{seed_name} case {k}"));
    }
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn gmsh_files_never_panic() {
    let mut rng = Rng(0x5eed_0001);
    for name in ["liver.msh", "liver2.msh"] {
        let text = std::fs::read(common::mesh_path(name)).unwrap();
        fuzz(name, &text, false, &mut rng);
    }
}

#[test]
fn vtk_files_never_panic() {
    let mut rng = Rng(0x5eed_0002);
    let dir = scratch("vtk-seed");
    let path = dir.join("seed.vtk");
    let m = lattice_box(Vec3::zeros(), Vec3::repeat(0.1), [3, 3, 3]);
    mesh::write_vtk(&path, &m).unwrap();
    let text = std::fs::read(&path).unwrap();
    fuzz("seed.vtk", &text, false, &mut rng);
}

#[test]
fn tetgen_files_never_panic() {
    // A TetGen mesh is two files: mutate one while the other stays whole.
    let mut rng = Rng(0x5eed_0003);
    let m = lattice_box(Vec3::zeros(), Vec3::repeat(0.1), [3, 3, 3]);
    let mut node = format!("{} 3 0 0\n", m.nodes.len());
    for (i, p) in m.nodes.iter().enumerate() {
        node += &format!("{i} {} {} {}\n", p.x, p.y, p.z);
    }
    let mut ele = format!("{} 4 0\n", m.tets.len());
    for (i, t) in m.tets.iter().enumerate() {
        ele += &format!("{i} {} {} {} {}\n", t[0], t[1], t[2], t[3]);
    }
    let dir = scratch("tetgen");
    for (mutated, whole, whole_text) in [("node", "ele", &ele), ("ele", "node", &node)] {
        let seed = if mutated == "node" { &node } else { &ele };
        std::fs::write(dir.join(format!("fuzz.{whole}")), whole_text).unwrap();
        for k in 0..cases() {
            let bytes = mutate(seed.as_bytes(), &mut rng);
            let path = dir.join(format!("fuzz.{mutated}"));
            std::fs::write(&path, &bytes).unwrap();
            load_never_panics(&path, false, &format!("tetgen .{mutated} case {k}"));
        }
    }
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn obj_files_never_panic() {
    let mut rng = Rng(0x5eed_0004);
    let cube = "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 0 0 1\nv 1 0 1\nv 1 1 1\nv 0 1 1\n\
                vn 0 0 1\nvt 0.5 0.5\n\
                f 1 2 3 4\nf 5/1/1 8/1/1 7/1/1 6/1/1\nf 1//1 5//1 6//1 2//1\n\
                f -5 -6 -2 -1\nf 1 4 8 5\nf 4 3 7 8\n";
    fuzz("cube.obj", cube.as_bytes(), true, &mut rng);
}
