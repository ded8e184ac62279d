//! Step timing of the haptic scene on the test livers (data/meshes): ms per step (median, p99,
//! max, mean), cost per particle, memory per particle; with and without a probe in contact.
//!
//! ```text
//! cargo bench --bench step -- [--meshes liver_1k6,liver_4k,liver_10k,liver_31k,three_organs]
//!                             [--steps N]
//!                             [--scene haptic|pypbd] [--threads N] [--csv PATH]
//!                             [--times PATH] [--particles] [--tet-volumes] [--paper]
//!                             [--self-contact] [--damping S] [--crushed-substeps N] [--profile]
//!                             [--settled]
//! ```
//! `--csv` writes the table; `--times` every timed step's time (ms), in order, one row a step.
//! Scenes:
//! - `haptic`: mesh scaled by 0.03 (~0.2 m), E = 5 kPa, ν = 0.45, ρ = 1060 kg/m³,
//!   dt = 1 ms, top 10% of the y range fixed, gravity;
//! - `pypbd` (the peer script `validation/peers/pypbd_liver.py`): mesh units, E = 3000, ν = 0.45,
//!   ρ = 1, dt = 1 ms, top 3% fixed, gravity 9.81.
//!
//! With `probe`, a sphere (radius 5% of the organ's size) is pressed into the side of the organ
//! by 15% of its size. `--threads` sets `Settings::threads` (default 1). The default settings put
//! the elasticity on corotated tetrahedra and one volume constraint on each particle's dual cell;
//! `--particles` puts the elasticity on the paper's point-based particles
//! (`ElasticScheme::PointBased`), `--tet-volumes` one volume constraint on each tetrahedron
//! (`VolumeScheme::Tetrahedra`), and `--paper` both: the paper's method.
//! `--self-contact` switches the surface self-contact on (`Settings::self_contact`);
//! `--damping S` sets the stiffness-proportional damping time β (s, `Settings::damping_stiffness`);
//! `--crushed-substeps N` the substeps of a step that starts with a crushed tetrahedron
//! (`Settings::crushed_substeps`);
//! `--profile` prints each stage's mean wall time per timed step (`World::step_profile`; the
//! clock reads add well under a microsecond a step).
//! `--settled` starts each organ at its static equilibrium under gravity (`World::settle`, as a
//! trainer does on loading) instead of at its rest shape, so that it does not sway in the timed
//! steps.
//!
//! Besides the meshes, `three_organs` is a multi-organ scene: liver_4k hanging, kidney_gmsh
//! under it (touching it, held at its bottom 10%) and liver_1k6 beside it (touching on the −x
//! side, hanging), all at the scene's scale and material, with organ–organ contact; the probe
//! presses liver_4k.

use std::alloc::{GlobalAlloc, Layout, System};
use std::path::PathBuf;
use std::sync::atomic::{AtomicUsize, Ordering};
use std::time::Instant;
use tissuesim::{
    mesh, BodyId, BodyOptions, ElasticScheme, Material, Pose, Real, Settings, ToolOptions,
    ToolShape, Vec3, VolumeScheme, World,
};

/// Counts live heap bytes, for memory per particle.
struct Counting;
static LIVE: AtomicUsize = AtomicUsize::new(0);
unsafe impl GlobalAlloc for Counting {
    unsafe fn alloc(&self, l: Layout) -> *mut u8 {
        LIVE.fetch_add(l.size(), Ordering::Relaxed);
        System.alloc(l)
    }
    unsafe fn dealloc(&self, p: *mut u8, l: Layout) {
        LIVE.fetch_sub(l.size(), Ordering::Relaxed);
        System.dealloc(p, l)
    }
    unsafe fn realloc(&self, p: *mut u8, l: Layout, n: usize) -> *mut u8 {
        LIVE.fetch_add(n, Ordering::Relaxed);
        LIVE.fetch_sub(l.size(), Ordering::Relaxed);
        System.realloc(p, l, n)
    }
}
#[global_allocator]
static GLOBAL: Counting = Counting;

struct Row {
    mesh: String,
    probe: bool,
    particles: usize,
    pairs: usize,
    substeps: u32,
    median: f64,
    p99: f64,
    max: f64,
    mean: f64,
    bytes: usize,
    contacts: u32,
    /// Every timed step's time (ms), in step order.
    series: Vec<f64>,
    /// With `--profile`: each stage's mean wall time per timed step (µs), in
    /// `StepProfile::stages` order.
    stages: Vec<(&'static str, f64)>,
}

fn percentile(sorted: &[f64], q: f64) -> f64 {
    let k = ((sorted.len() - 1) as f64 * q).round() as usize;
    sorted[k]
}

/// A benchmark scene: mesh scale, material, fixed fraction of the height.
#[derive(Clone, Copy)]
struct Scene {
    scale: Real,
    material: Material,
    fixed_fraction: Real,
}

fn scene(name: &str) -> Scene {
    match name {
        "haptic" => Scene {
            scale: 0.03,
            material: Material {
                youngs_modulus: 5.0e3,
                poisson_ratio: 0.45,
                density: 1060.0,
            },
            fixed_fraction: 0.1,
        },
        "pypbd" => Scene {
            scale: 1.0,
            material: Material {
                youngs_modulus: 3.0e3,
                poisson_ratio: 0.45,
                density: 1.0,
            },
            fixed_fraction: 0.03,
        },
        other => panic!("unknown scene {other} (haptic or pypbd)"),
    }
}

/// The TetGen mesh `file` in `$TISSUESIM_MESHES` when set, else in the repository's
/// `data/meshes`; panics naming the full path looked at when it is not there.
fn mesh_path(file: &str) -> PathBuf {
    let env = std::env::var_os("TISSUESIM_MESHES");
    let dir = match &env {
        Some(dir) => PathBuf::from(dir),
        None => PathBuf::from(concat!(env!("CARGO_MANIFEST_DIR"), "/data/meshes")),
    };
    let path = dir.join(file);
    if !path.is_file() {
        let from = match env {
            Some(dir) => format!("TISSUESIM_MESHES={}", dir.to_string_lossy()),
            None => "TISSUESIM_MESHES is not set, so the repository's data/meshes".to_string(),
        };
        panic!(
            "mesh not found: {} (looked there because {from})",
            path.display()
        );
    }
    path
}

/// The mesh `name` scaled by `scale` and centred on the origin.
fn centred_mesh(name: &str, scale: Real) -> mesh::TetMesh {
    let path = mesh_path(&format!("{name}.node"));
    let (mut organ, _) = mesh::load(&path, scale).unwrap_or_else(|e| panic!("{e}"));
    let (lo, hi) = organ.bounding_box();
    let centre = (lo + hi) * 0.5;
    for p in &mut organ.nodes {
        *p -= centre;
    }
    organ
}

/// Add `organ` moved by `offset` (m) to `world`, its particles within `fraction` of its height
/// from the top (`from_top`) or the bottom fixed; returns the body and its bounding box.
fn add_organ(
    world: &mut World,
    organ: &mesh::TetMesh,
    offset: Vec3,
    options: &BodyOptions,
    (fraction, from_top): (Real, bool),
) -> (BodyId, Vec3, Vec3) {
    let mut moved = organ.clone();
    moved.nodes.iter_mut().for_each(|p| *p += offset);
    let (lo, hi) = moved.bounding_box();
    let body = world.add_body(&moved, options).unwrap();
    let far = 10.0 * (hi - lo).max();
    let (bottom, top) = if from_top {
        (hi.y - fraction * (hi.y - lo.y), hi.y + far)
    } else {
        (lo.y - far, lo.y + fraction * (hi.y - lo.y))
    };
    world
        .fix_box(
            body,
            Vec3::new(lo.x - far, bottom, lo.z - far),
            Vec3::new(hi.x + far, top, hi.z + far),
        )
        .unwrap();
    (body, lo, hi)
}

/// The organs of the scene `name`: one mesh hanging from its top, or `three_organs` — liver_4k
/// hanging, kidney_gmsh under it (touching, held at its bottom) and liver_1k6 beside it
/// (touching on the −x side, hanging): organ–organ contact in the step. Returns the bodies and
/// the bounding box of the first (the one the probe presses).
fn add_organs(world: &mut World, name: &str, scene: Scene) -> (Vec<BodyId>, Vec3, Vec3) {
    let options = BodyOptions {
        material: scene.material,
        ..BodyOptions::default()
    };
    let hanging = (scene.fixed_fraction, true);
    if name != "three_organs" {
        let organ = centred_mesh(name, scene.scale);
        let (body, lo, hi) = add_organ(world, &organ, Vec3::zeros(), &options, hanging);
        return (vec![body], lo, hi);
    }
    let liver = centred_mesh("liver_4k", scene.scale);
    let (a, lo, hi) = add_organ(world, &liver, Vec3::zeros(), &options, hanging);
    let kidney = centred_mesh("kidney_gmsh", scene.scale);
    let below = Vec3::new(0.0, lo.y - kidney.bounding_box().1.y, 0.0);
    let (b, ..) = add_organ(
        world,
        &kidney,
        below,
        &options,
        (scene.fixed_fraction, false),
    );
    let lobe = centred_mesh("liver_1k6", scene.scale);
    let beside = Vec3::new(lo.x - lobe.bounding_box().1.x, 0.0, 0.0);
    let (c, ..) = add_organ(world, &lobe, beside, &options, hanging);
    (vec![a, b, c], lo, hi)
}

fn run(
    name: &str,
    scene: Scene,
    probe: bool,
    (steps, profile, settled): (usize, bool, bool),
    settings: &Settings,
) -> Row {
    let live0 = LIVE.load(Ordering::Relaxed);
    let mut world = World::new(settings.clone()).unwrap();
    let (bodies, lo, hi) = add_organs(&mut world, name, scene);
    if settled {
        world.settle().unwrap();
    }
    let top = hi.y - scene.fixed_fraction * (hi.y - lo.y);
    let organ_nodes: Vec<Vec3> = world.body(bodies[0]).unwrap().rest_positions().to_vec();
    let bytes = LIVE.load(Ordering::Relaxed) - live0;
    // The probe: a sphere on the +z side at mid-height, moved in along -z until it is pressed
    // `press` past the first particle it meets.
    let size = (hi - lo).max();
    let radius = 0.05 * size;
    let press = 0.15 * size;
    let y_mid = 0.5 * (lo.y + top);
    let surface_z = organ_nodes
        .iter()
        .filter(|p| (p.x.powi(2) + (p.y - y_mid).powi(2)).sqrt() < radius)
        .map(|p| p.z)
        .fold(lo.z, Real::max);
    let start = Vec3::new(0.0, y_mid, surface_z + radius + 0.05 * size);
    let pressed = start - Vec3::new(0.0, 0.0, 0.05 * size + press);
    let tool = if probe {
        Some(
            world
                .add_tool(
                    ToolShape::Sphere { radius },
                    Pose::at(start),
                    &ToolOptions::default(),
                )
                .unwrap(),
        )
    } else {
        None
    };
    // Warm-up: the probe moves in over 0.5 s, then everything settles for 0.5 s.
    for k in 1..=1000 {
        if let Some(t) = tool {
            let s = (k as Real / 500.0).min(1.0);
            world
                .set_tool_pose(t, Pose::at(start.lerp(&pressed, s)))
                .unwrap();
        }
        world.step().unwrap();
    }
    let mut times = Vec::with_capacity(steps);
    let mut contacts = 0;
    world.set_profiling(profile);
    let mut stage_sums: Vec<(&'static str, f64)> = Vec::new();
    for k in 0..steps {
        if let Some(t) = tool {
            // A small oscillation keeps the contact alive and changing.
            let wobble = Vec3::new(0.0, 0.0, 0.01 * size * ((k as Real) * 0.01).sin());
            world.set_tool_pose(t, Pose::at(pressed + wobble)).unwrap();
        }
        let t0 = Instant::now();
        world.step().unwrap();
        times.push(t0.elapsed().as_secs_f64() * 1e3);
        if let Some(p) = world.step_profile() {
            let now = p.stages();
            stage_sums.resize(now.len(), ("", 0.0));
            for (sum, (name, time)) in stage_sums.iter_mut().zip(now) {
                *sum = (name, sum.1 + time.as_secs_f64() * 1e6 / steps as f64);
            }
        }
        if let Some(t) = tool {
            contacts = contacts.max(world.tool(t).unwrap().wrench().contact_count);
        }
    }
    let mean = times.iter().sum::<f64>() / times.len() as f64;
    let series = times.clone();
    times.sort_by(|a, b| a.total_cmp(b));
    let (mut particles, mut pairs) = (0, 0);
    for &b in &bodies {
        let b = world.body(b).unwrap();
        particles += b.particle_count();
        pairs += b.neighbourhoods().pair_count();
    }
    Row {
        mesh: name.to_string(),
        probe,
        particles,
        pairs,
        substeps: world.substeps_needed().0,
        median: percentile(&times, 0.5),
        p99: percentile(&times, 0.99),
        max: *times.last().unwrap(),
        mean,
        bytes,
        contacts,
        series,
        stages: stage_sums,
    }
}

fn main() {
    let mut meshes = vec![
        "liver_1k6".to_string(),
        "liver_4k".to_string(),
        "liver_10k".to_string(),
        "liver_31k".to_string(),
    ];
    let mut steps = 2000;
    let mut csv: Option<PathBuf> = None;
    let mut times_csv: Option<PathBuf> = None;
    let mut scene_name = "haptic".to_string();
    let mut threads = 1;
    let mut volume_scheme = Settings::default().volume_scheme;
    let mut elastic_scheme = Settings::default().elastic_scheme;
    let mut self_contact = false;
    let mut damping_stiffness = Settings::default().damping_stiffness;
    let mut crushed_substeps = Settings::default().crushed_substeps;
    let mut profile = false;
    let mut settled = false;
    let mut args = std::env::args().skip(1);
    while let Some(a) = args.next() {
        match a.as_str() {
            "--meshes" => {
                meshes = args
                    .next()
                    .expect("--meshes LIST")
                    .split(',')
                    .map(String::from)
                    .collect()
            }
            "--steps" => steps = args.next().expect("--steps N").parse().expect("a number"),
            "--csv" => csv = Some(PathBuf::from(args.next().expect("--csv PATH"))),
            "--times" => times_csv = Some(PathBuf::from(args.next().expect("--times PATH"))),
            "--scene" => scene_name = args.next().expect("--scene haptic|pypbd"),
            "--threads" => threads = args.next().expect("--threads N").parse().expect("a number"),
            "--particles" => elastic_scheme = ElasticScheme::PointBased,
            "--tet-volumes" => volume_scheme = VolumeScheme::Tetrahedra,
            "--paper" => {
                elastic_scheme = ElasticScheme::PointBased;
                volume_scheme = VolumeScheme::Tetrahedra;
            }
            "--self-contact" => self_contact = true,
            "--damping" => {
                damping_stiffness = (args.next().expect("--damping SECONDS"))
                    .parse()
                    .expect("a number of seconds")
            }
            "--crushed-substeps" => {
                crushed_substeps = (args.next().expect("--crushed-substeps N"))
                    .parse()
                    .expect("a number of substeps")
            }
            "--profile" => profile = true,
            "--settled" => settled = true,
            "--bench" => {}
            other => panic!("unknown argument {other}"),
        }
    }
    println!(
        "{:<10} {:>5} {:>9} {:>8} {:>4} {:>8} {:>8} {:>8} {:>8} {:>10} {:>8} {:>5}",
        "mesh",
        "probe",
        "particles",
        "pairs",
        "sub",
        "median",
        "p99",
        "max",
        "mean",
        "us/1k part",
        "B/part",
        "cont"
    );
    let mut out = String::from(
        "scene,threads,mesh,probe,particles,pairs,substeps,median_ms,p99_ms,max_ms,mean_ms,us_per_1000_particles,bytes_per_particle,contacts\n",
    );
    let mut series = String::from("scene,threads,mesh,probe,step,ms\n");
    for m in &meshes {
        for probe in [false, true] {
            let r = run(
                m,
                scene(&scene_name),
                probe,
                (steps, profile, settled),
                &Settings {
                    threads,
                    volume_scheme,
                    elastic_scheme,
                    self_contact,
                    damping_stiffness,
                    crushed_substeps,
                    ..Settings::default()
                },
            );
            let per_k = r.median * 1e3 / r.particles as f64 * 1e3;
            let bpp = r.bytes as f64 / r.particles as f64;
            println!(
                "{:<10} {:>5} {:>9} {:>8} {:>4} {:>8.3} {:>8.3} {:>8.3} {:>8.3} {:>10.1} {:>8.0} {:>5}",
                r.mesh, r.probe, r.particles, r.pairs, r.substeps, r.median, r.p99, r.max, r.mean, per_k, bpp, r.contacts
            );
            for (stage, us) in &r.stages {
                println!("    {stage:<16} {us:>9.1} us/step (mean)");
            }
            out += &format!(
                "{},{},{},{},{},{},{},{:.4},{:.4},{:.4},{:.4},{:.2},{:.0},{}\n",
                scene_name,
                threads,
                r.mesh,
                r.probe,
                r.particles,
                r.pairs,
                r.substeps,
                r.median,
                r.p99,
                r.max,
                r.mean,
                per_k,
                bpp,
                r.contacts
            );
            for (k, ms) in r.series.iter().enumerate() {
                series += &format!(
                    "{scene_name},{threads},{},{},{k},{ms:.4}\n",
                    r.mesh, r.probe
                );
            }
        }
    }
    for (path, text) in [(csv, out), (times_csv, series)] {
        if let Some(path) = path {
            std::fs::write(&path, text).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
        }
    }
}
