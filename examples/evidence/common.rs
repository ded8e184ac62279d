//! Helpers shared by the subcommands: meshes, the DESIGN §7 scene, fixing, probe placement,
//! tetrahedron checks and small file writers.

use std::fs::File;
use std::io::{BufWriter, Write};
use std::path::{Path, PathBuf};
use tissuesim::mesh::{self, TetMesh};
use tissuesim::{BodyId, BodyOptions, Material, Real, Settings, Vec3, World};

/// Result type of the subcommands.
pub type Res<T> = Result<T, Box<dyn std::error::Error>>;

/// Folder of the test meshes: `$TISSUESIM_MESHES` when set, else the repository's `data/meshes`.
pub fn mesh_dir() -> PathBuf {
    match std::env::var_os("TISSUESIM_MESHES") {
        Some(p) => PathBuf::from(p),
        None => PathBuf::from(concat!(env!("CARGO_MANIFEST_DIR"), "/data/meshes")),
    }
}

/// The path of the mesh file `file` in [`mesh_dir`], or an error naming the full path looked at
/// and where the folder came from.
pub fn mesh_path(file: &str) -> Res<PathBuf> {
    let path = mesh_dir().join(file);
    if path.is_file() {
        return Ok(path);
    }
    let from = match std::env::var_os("TISSUESIM_MESHES") {
        Some(dir) => format!("TISSUESIM_MESHES={}", dir.to_string_lossy()),
        None => "TISSUESIM_MESHES is not set, so the repository's data/meshes".to_string(),
    };
    Err(format!(
        "mesh not found: {} (looked there because {from})",
        path.display()
    )
    .into())
}

/// Load a TetGen test mesh (`name` without extension) at `scale`, checking that the loader kept
/// the file's node order (no unreferenced node removed), so that particle `i` is TetGen node `i`.
pub fn load_mesh(name: &str, scale: Real) -> Res<TetMesh> {
    let path = mesh_path(&format!("{name}.node"))?;
    let (m, report) = mesh::load(&path, scale)?;
    let identity = report
        .original_node_index
        .iter()
        .enumerate()
        .all(|(i, &k)| i == k as usize);
    if report.unreferenced_nodes_removed != 0 || !identity {
        return Err(format!(
            "{}: the loader renumbered nodes ({} unreferenced removed)",
            path.display(),
            report.unreferenced_nodes_removed
        )
        .into());
    }
    Ok(m)
}

/// The DESIGN §7 liver: a test liver scaled by 0.03 (~0.2 m) and centred on the origin.
pub fn design_liver(name: &str) -> Res<TetMesh> {
    let mut m = load_mesh(name, 0.03)?;
    let (lo, hi) = m.bounding_box();
    let c = (lo + hi) * 0.5;
    for p in &mut m.nodes {
        *p -= c;
    }
    Ok(m)
}

/// The DESIGN §7 material: E = 5 kPa, ν = 0.45, ρ = 1060 kg/m³.
pub fn design_options() -> BodyOptions {
    BodyOptions {
        material: Material {
            youngs_modulus: 5.0e3,
            poisson_ratio: 0.45,
            density: 1060.0,
        },
        ..BodyOptions::default()
    }
}

/// The DESIGN §7 scene: `liver` mesh scaled 0.03, default settings (dt 1 ms) changed by `edit`,
/// the top 10% of its height fixed.
pub fn design_scene(name: &str, settings: Settings) -> Res<(World, BodyId)> {
    let mut world = World::new(settings)?;
    let id = world.add_body(&design_liver(name)?, &design_options())?;
    fix_top(&mut world, id, 0.1)?;
    Ok((world, id))
}

/// Fix every particle with y ≥ ymax − fraction·(ymax − ymin); returns how many.
pub fn fix_top(world: &mut World, id: BodyId, fraction: Real) -> Res<usize> {
    let (lo, hi) = bounds(world.body(id)?.positions());
    let y = hi.y - fraction * (hi.y - lo.y);
    let big = Vec3::repeat(1.0e3);
    Ok(world.fix_box(
        id,
        Vec3::new(lo.x, y, lo.z) - Vec3::new(1.0e3, 0.0, 1.0e3),
        hi + big,
    )?)
}

/// Axis-aligned bounds of points.
pub fn bounds(points: &[Vec3]) -> (Vec3, Vec3) {
    points.iter().fold(
        (Vec3::repeat(Real::MAX), Vec3::repeat(Real::MIN)),
        |(lo, hi), p| (lo.inf(p), hi.sup(p)),
    )
}

/// Distance `s` such that a sphere of `radius` centred at `origin - direction·s` first touches the
/// particles (contact at `radius + particle_radius`), coming from far away along `direction`.
pub fn touch_distance(
    points: &[Vec3],
    origin: Vec3,
    direction: Vec3,
    radius: Real,
    particle_radius: Real,
) -> Real {
    let gap = |s: Real| {
        let c = origin - direction * s;
        points
            .iter()
            .map(|p| (p - c).norm() - radius - particle_radius)
            .fold(Real::INFINITY, Real::min)
    };
    let (mut lo, mut hi) = (0.0, 10.0);
    for _ in 0..80 {
        let mid = 0.5 * (lo + hi);
        if gap(mid) > 0.0 {
            hi = mid;
        } else {
            lo = mid;
        }
    }
    hi
}

/// Signed volumes of the tetrahedra at positions `x` (m³).
pub fn tet_volumes(x: &[Vec3], tets: &[[u32; 4]]) -> Vec<Real> {
    tets.iter()
        .map(|t| {
            let [a, b, c, d] = t.map(|k| x[k as usize]);
            (b - a).cross(&(c - a)).dot(&(d - a)) / 6.0
        })
        .collect()
}

/// Number of inverted (signed volume ≤ 0) tetrahedra and the smallest `V/V0`.
pub fn inversion_stats(world: &World, id: BodyId) -> Res<(usize, Real)> {
    let b = world.body(id)?;
    let now = tet_volumes(b.positions(), b.tets());
    let rest = tet_volumes(b.rest_positions(), b.tets());
    let inverted = now.iter().filter(|&&v| v <= 0.0).count();
    let min_ratio = now
        .iter()
        .zip(&rest)
        .map(|(v, v0)| v / v0)
        .fold(Real::INFINITY, Real::min);
    Ok((inverted, min_ratio))
}

/// Largest particle speed of a body (m/s).
pub fn max_speed(world: &World, id: BodyId) -> Res<Real> {
    Ok(world
        .body(id)?
        .velocities()
        .iter()
        .map(|v| v.norm())
        .fold(0.0, Real::max))
}

/// A buffered text file, parent folders created.
pub fn create(path: &Path) -> Res<BufWriter<File>> {
    if let Some(parent) = path.parent() {
        if !parent.as_os_str().is_empty() {
            std::fs::create_dir_all(parent)?;
        }
    }
    Ok(BufWriter::new(File::create(path)?))
}

/// Write positions as CSV `x,y,z` (one row per particle).
pub fn write_positions(path: &Path, x: &[Vec3]) -> Res<()> {
    let mut f = create(path)?;
    writeln!(f, "x,y,z")?;
    for p in x {
        writeln!(f, "{:.9e},{:.9e},{:.9e}", p.x, p.y, p.z)?;
    }
    Ok(())
}

/// Write triangles as CSV `a,b,c`.
pub fn write_triangles(path: &Path, tris: &[[u32; 3]]) -> Res<()> {
    let mut f = create(path)?;
    writeln!(f, "a,b,c")?;
    for t in tris {
        writeln!(f, "{},{},{}", t[0], t[1], t[2])?;
    }
    Ok(())
}

/// Write a body's state as VTU (displacement and speed as point data).
pub fn write_vtu(path: &Path, world: &World, id: BodyId) -> Res<()> {
    let b = world.body(id)?;
    if let Some(parent) = path.parent() {
        std::fs::create_dir_all(parent)?;
    }
    let u: Vec<Vec3> = b
        .positions()
        .iter()
        .zip(b.rest_positions())
        .map(|(x, r)| x - r)
        .collect();
    let speed: Vec<Real> = b.velocities().iter().map(|v| v.norm()).collect();
    mesh::write_vtu(
        path,
        b.positions(),
        b.tets(),
        &[("speed", &speed)],
        &[("displacement", &u), ("velocity", b.velocities())],
    )?;
    Ok(())
}

/// Percentile `q` in [0, 1] of `v` (sorted copy, nearest rank).
pub fn percentile(v: &[Real], q: Real) -> Real {
    let mut s = v.to_vec();
    s.sort_by(|a, b| a.partial_cmp(b).unwrap());
    let k = ((q * s.len() as Real).ceil() as usize).clamp(1, s.len()) - 1;
    s[k]
}
