//! Helpers shared by the integration tests: mesh paths, scene builders, rigid alignment.
#![allow(dead_code)]

use std::path::PathBuf;
use tissuesim::mesh::{self, TetMesh};
use tissuesim::{BodyId, BodyOptions, Material, Real, Settings, Vec3, World};

/// The folder of the test meshes: `$TISSUESIM_MESHES` when set, else `data/meshes` in the
/// repository (see data/meshes/README.md).
pub fn mesh_dir() -> PathBuf {
    match std::env::var_os("TISSUESIM_MESHES") {
        Some(dir) => PathBuf::from(dir),
        None => PathBuf::from(concat!(env!("CARGO_MANIFEST_DIR"), "/data/meshes")),
    }
}

/// The path of the test mesh `file` in [`mesh_dir`] (a file name, or a TetGen base name without
/// `.node`/`.ele`). Panics, naming the full path looked at and the environment variable, when the
/// file is not there: a test never skips for missing data.
pub fn mesh_path(file: &str) -> PathBuf {
    let path = mesh_dir().join(file);
    let tetgen_base = || {
        let mut node = path.clone().into_os_string();
        node.push(".node");
        PathBuf::from(node).is_file()
    };
    if !path.is_file() && !tetgen_base() {
        let from = match std::env::var_os("TISSUESIM_MESHES") {
            Some(dir) => format!("TISSUESIM_MESHES={}", dir.to_string_lossy()),
            None => "TISSUESIM_MESHES is not set, so the repository's data/meshes".to_string(),
        };
        panic!(
            "test mesh not found: {} (looked there because {from}; set TISSUESIM_MESHES to a \
             folder holding the files of data/meshes/README.md)",
            path.display()
        );
    }
    path
}

/// A liver mesh of [`mesh_dir`] scaled by 0.03 (about 0.19 × 0.15 × 0.13 m) and translated so
/// that its bounding box is centred on the origin.
pub fn liver(file: &str) -> TetMesh {
    let mut mesh = mesh::load(&mesh_path(file), 0.03)
        .unwrap_or_else(|e| panic!("{e}"))
        .0;
    let (lo, hi) = mesh.bounding_box();
    let centre = (lo + hi) * 0.5;
    for p in &mut mesh.nodes {
        *p -= centre;
    }
    mesh
}

/// A 12 × 3 × 3 cm bar of firm tissue along x (E = 100 kPa, the default ν and ρ), cells of
/// 1.5 cm, centred on the origin: the cutting and shared-model scenes.
pub fn firm_bar() -> (TetMesh, BodyOptions) {
    let mesh = mesh::lattice_box(
        Vec3::new(-0.06, -0.015, -0.015),
        Vec3::new(0.06, 0.015, 0.015),
        [8, 2, 2],
    );
    let options = BodyOptions {
        material: Material {
            youngs_modulus: 1e5,
            ..Material::default()
        },
        ..BodyOptions::default()
    };
    (mesh, options)
}

/// The DESIGN §7 material: E = 5 kPa, ν = 0.45, ρ = 1060 kg/m³.
pub fn tissue() -> BodyOptions {
    BodyOptions {
        material: Material {
            youngs_modulus: 5.0e3,
            poisson_ratio: 0.45,
            density: 1060.0,
        },
        ..BodyOptions::default()
    }
}

/// Fix every particle in the top `fraction` of the body's y range; returns how many.
pub fn fix_top(world: &mut World, body: BodyId, fraction: Real) -> usize {
    let b = world.body(body).unwrap();
    let (mut lo, mut hi) = (Vec3::repeat(Real::MAX), Vec3::repeat(Real::MIN));
    for p in b.positions() {
        lo = lo.inf(p);
        hi = hi.sup(p);
    }
    let y = hi.y - fraction * (hi.y - lo.y);
    world
        .fix_box(
            body,
            Vec3::new(lo.x - 1.0, y, lo.z - 1.0),
            Vec3::new(hi.x + 1.0, hi.y + 1.0, hi.z + 1.0),
        )
        .unwrap()
}

/// Settings without gravity.
pub fn weightless() -> Settings {
    Settings {
        gravity: Vec3::zeros(),
        ..Settings::default()
    }
}

/// The paper's method: point-based (MLS) particles with per-tetrahedron volume constraints,
/// selectable beside the default (tetrahedra with dual-cell volume constraints).
pub fn paper(settings: Settings) -> Settings {
    Settings {
        elastic_scheme: tissuesim::ElasticScheme::PointBased,
        volume_scheme: tissuesim::VolumeScheme::Tetrahedra,
        ..settings
    }
}

/// Axis-aligned bounding box (min, max) of points.
pub fn bounds(points: &[Vec3]) -> (Vec3, Vec3) {
    let mut lo = points[0];
    let mut hi = points[0];
    for p in points {
        lo = lo.inf(p);
        hi = hi.sup(p);
    }
    (lo, hi)
}

/// A world with `settings` and two bodies, one above the other so that they touch as they sag:
/// liver_1k6 (its top 10% fixed) and below it the default organ moved 13 cm down (nothing fixed).
/// Returns the world and the two bodies' ids, upper first.
pub fn two_bodies_stacked(settings: Settings) -> (World, BodyId, BodyId) {
    let mut world = World::new(settings).unwrap();
    let a = world.add_body(&liver("liver_1k6.node"), &tissue()).unwrap();
    fix_top(&mut world, a, 0.1);
    let mut organ = mesh::default_organ();
    for p in &mut organ.nodes {
        *p += Vec3::new(0.0, -0.13, 0.0);
    }
    let b = world.add_body(&organ, &tissue()).unwrap();
    (world, a, b)
}

/// Where a press along the unit `direction` on the line through `through` (m) starts: the
/// centre (m) of a sphere of `radius` (m) `gap` (m) clear of the contact skin over the first
/// particle within 1 cm of the line. Panics when no particle is that near the line.
pub fn press_start(
    positions: &[Vec3],
    skin: Real,
    (through, direction): (Vec3, Vec3),
    radius: Real,
    gap: Real,
) -> Vec3 {
    let surface = positions
        .iter()
        .map(|p| p - through)
        .filter(|q| (q - direction * q.dot(&direction)).norm() < 0.01)
        .map(|q| q.dot(&direction))
        .fold(Real::INFINITY, Real::min);
    assert!(surface.is_finite(), "no particle on the press line");
    through + direction * (surface - skin - gap - radius)
}

/// Largest distance between `x` and the rigid motion of `rest` that best fits it (Kabsch,
/// weights `w`): the deformation left once translation and rotation are removed (m).
pub fn max_residual_after_rigid_fit(rest: &[Vec3], x: &[Vec3], w: &[Real]) -> Real {
    let wsum: Real = w.iter().sum();
    let c0: Vec3 = rest.iter().zip(w).map(|(p, m)| p * *m).sum::<Vec3>() / wsum;
    let c1: Vec3 = x.iter().zip(w).map(|(p, m)| p * *m).sum::<Vec3>() / wsum;
    let mut h = tissuesim::Mat3::zeros();
    for ((p, q), m) in rest.iter().zip(x).zip(w) {
        h += (q - c1) * (p - c0).transpose() * *m;
    }
    let svd = h.svd(true, true);
    let (u, vt) = (svd.u.unwrap(), svd.v_t.unwrap());
    let mut d = tissuesim::Mat3::identity();
    d[(2, 2)] = (u * vt).determinant().signum();
    let r = u * d * vt;
    rest.iter()
        .zip(x)
        .map(|(p, q)| (r * (p - c0) + c1 - q).norm())
        .fold(0.0, Real::max)
}

/// Signed volumes of every tetrahedron at positions `x` (m³).
pub fn tet_volumes(x: &[Vec3], tets: &[[u32; 4]]) -> Vec<Real> {
    tets.iter()
        .map(|t| {
            let [a, b, c, d] = t.map(|k| x[k as usize]);
            tissuesim::tet_volume(&a, &b, &c, &d)
        })
        .collect()
}

/// A deterministic pseudo-random sequence in [-1, 1] (xorshift), for perturbations.
pub struct Noise(u64);

impl Noise {
    pub fn new(seed: u64) -> Self {
        Noise(seed.max(1))
    }
    pub fn next(&mut self) -> Real {
        self.0 ^= self.0 << 13;
        self.0 ^= self.0 >> 7;
        self.0 ^= self.0 << 17;
        (self.0 >> 11) as Real / (1u64 << 53) as Real * 2.0 - 1.0
    }
    pub fn vec(&mut self) -> Vec3 {
        Vec3::new(self.next(), self.next(), self.next())
    }
}
