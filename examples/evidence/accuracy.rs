//! Static equilibria by dynamic relaxation, written as node displacements for comparison with
//! the scikit-fem references of `validation/reference/` (issue #6 item 1).
//!
//! A run steps the world with strong mass damping α until the largest particle speed `v_max`
//! satisfies `v_max / α < tol · max|u|` (the distance a particle would still creep at that speed
//! over the damping time 1/α, relative to the largest displacement), or until a step cap.

use crate::common::{create, load_mesh, max_speed, Res};
use crate::Args;
use std::io::Write;
use std::path::{Path, PathBuf};
use std::time::Instant;
use tissuesim::mesh::{self, TetMesh};
use tissuesim::{BodyId, BodyOptions, Material, Real, Settings, Vec3, World};

/// One static run's configuration.
#[derive(Clone, Debug)]
pub struct StaticRun {
    /// `cantilever`, `liver030` or `liver045`.
    pub scene: String,
    /// Settings::volume_constraints.
    pub volume_constraints: bool,
    /// BodyOptions::target_neighbours.
    pub neighbours: u32,
    /// Settings::hourglass_stiffness.
    pub hourglass: Real,
    /// Settings::iterations.
    pub iterations: u32,
    /// Settings::dt (scene units of time: s).
    pub dt: Real,
    /// Settings::damping_mass (1/s).
    pub damping: Real,
    /// Settings::min_substeps.
    pub min_substeps: u32,
    /// Relative convergence tolerance.
    pub tol: Real,
    /// Step cap.
    pub max_steps: usize,
    /// Length scale applied to the liver mesh (a check of unit independence: dt and 1/α scale
    /// with it, displacements are written divided by scale²).
    pub scale: Real,
}

impl StaticRun {
    fn defaults(scene: &str) -> StaticRun {
        // Mass damping near critical for the lowest mode (ω₁ ≈ 14 rad/s for the beam, ≈ 8 rad/s
        // for the liver in mesh units); dt such that the stability limit needs a few substeps.
        let (dt, damping) = if scene == "cantilever" {
            (1.0e-3, 25.0)
        } else {
            (2.0e-3, 15.0)
        };
        StaticRun {
            scene: scene.to_string(),
            volume_constraints: true,
            neighbours: 20,
            hourglass: Settings::default().hourglass_stiffness,
            iterations: 1,
            dt,
            damping,
            min_substeps: 1,
            tol: 1.0e-6,
            max_steps: 40_000,
            scale: 1.0,
        }
    }
    fn from_args(args: &Args) -> Res<StaticRun> {
        let scene = args.string("scene", "liver030");
        let d = StaticRun::defaults(&scene);
        Ok(StaticRun {
            volume_constraints: !args.flag("no-volume"),
            neighbours: args.get("neighbours", d.neighbours)?,
            hourglass: args.get("hourglass", d.hourglass)?,
            iterations: args.get("iterations", d.iterations)?,
            dt: args.get("dt", d.dt)?,
            damping: args.get("damping", d.damping)?,
            min_substeps: args.get("min-substeps", d.min_substeps)?,
            tol: args.get("tol", d.tol)?,
            max_steps: args.get("max-steps", d.max_steps)?,
            scale: args.get("scale", 1.0)?,
            scene,
        })
    }
}

/// What a static run gave.
pub struct StaticResult {
    /// (node id in the reference's numbering, displacement) per particle, in particle order.
    pub rows: Vec<(usize, Vec3)>,
    /// Substeps per step.
    pub substeps: u32,
    /// Steps taken.
    pub steps: usize,
    /// `v_max / (α max|u|)` at the end.
    pub residual: Real,
    /// Largest displacement (in the reference's units: divided by scale²).
    pub max_u: Real,
    /// Volume ratio at the end.
    pub volume_ratio: Real,
    /// Fixed particles.
    pub fixed: usize,
    /// Wall-clock seconds.
    pub seconds: Real,
    /// True when the tolerance was reached before the step cap.
    pub converged: bool,
}

/// Factor on the beam's gravity: the reference is linear elasticity, and at full gravity the
/// 0.1 m beam's linear tip deflection (7.5 cm) is far outside small strain; the solver is
/// geometrically nonlinear (corotated), so the beam runs at 1/1000 of the load and its
/// displacements are scaled back by 1000 (the linear reference scales exactly).
const BEAM_LOAD_FACTOR: Real = 1.0e-3;

/// Gravity factor of a scene (see [`BEAM_LOAD_FACTOR`]).
fn load_factor(scene: &str) -> Real {
    if scene == "cantilever" {
        BEAM_LOAD_FACTOR
    } else {
        1.0
    }
}

/// Build the scene: mesh, material, gravity, fixed particles.
fn build(run: &StaticRun) -> Res<(World, BodyId, TetMesh, usize)> {
    let (mesh, material, g) = match run.scene.as_str() {
        "cantilever" => (
            mesh::lattice_box(
                Vec3::new(0.0, -0.01, -0.01),
                Vec3::new(0.1, 0.01, 0.01),
                [20, 4, 4],
            ),
            Material {
                youngs_modulus: 5.0e4,
                poisson_ratio: 0.3,
                density: 1000.0,
            },
            9.81 * BEAM_LOAD_FACTOR,
        ),
        "liver030" | "liver045" => (
            load_mesh("liver_4k", run.scale)?,
            Material {
                youngs_modulus: 3000.0,
                poisson_ratio: if run.scene == "liver030" { 0.3 } else { 0.45 },
                density: 1.0,
            },
            0.981,
        ),
        s => return Err(format!("unknown scene {s} (cantilever, liver030, liver045)").into()),
    };
    let settings = Settings {
        dt: run.dt * run.scale,
        gravity: Vec3::new(0.0, -g, 0.0),
        damping_mass: run.damping / run.scale,
        hourglass_stiffness: run.hourglass,
        volume_constraints: run.volume_constraints,
        iterations: run.iterations,
        min_substeps: run.min_substeps,
        max_substeps: 256,
        ..Settings::default()
    };
    let mut world = World::new(settings)?;
    let options = BodyOptions {
        material,
        target_neighbours: run.neighbours,
        ..BodyOptions::default()
    };
    let id = world.add_body(&mesh, &options)?;
    let fixed = if run.scene == "cantilever" {
        world.fix_box(id, Vec3::new(-1.0, -1.0, -1.0), Vec3::new(1e-12, 1.0, 1.0))?
    } else {
        let (lo, hi) = mesh.bounding_box();
        let thr = hi.y - 0.1 * (hi.y - lo.y);
        let nodes: Vec<u32> = (0..mesh.nodes.len() as u32)
            .filter(|&k| mesh.nodes[k as usize].y >= thr)
            .collect();
        let particles = world.body(id)?.particle_order().particles_of(&nodes);
        world.fix_particles(id, &particles.ok_or("fixed node out of range")?)?;
        nodes.len()
    };
    Ok((world, id, mesh, fixed))
}

/// Node id of mesh node `k` in the reference CSV's numbering.
fn node_id(scene: &str, mesh: &TetMesh, k: usize) -> usize {
    if scene == "cantilever" {
        // Lattice index i + 21 (j + 5 k) from the rest position (spacing 5 mm).
        let p = mesh.nodes[k];
        let c = |v: Real, lo: Real| ((v - lo) / 0.005).round() as usize;
        c(p.x, 0.0) + 21 * (c(p.y, -0.01) + 5 * c(p.z, -0.01))
    } else {
        k
    }
}

/// Run to static equilibrium.
pub fn run_static(run: &StaticRun) -> Res<StaticResult> {
    let (mut world, id, mesh, fixed) = build(run)?;
    let substeps = world.substeps_needed().0;
    let start = Instant::now();
    let mut steps = 0;
    let mut residual = Real::INFINITY;
    let min_steps = (3.0 / (run.damping * run.dt)).ceil() as usize;
    if run.scene == "cantilever" && run.scale != 1.0 {
        return Err("--scale applies to the liver scenes only".into());
    }
    while steps < run.max_steps {
        world.step()?;
        steps += 1;
        if steps % 10 == 0 || steps >= run.max_steps {
            let umax = world.body(id)?.max_displacement();
            let v = max_speed(&world, id)?;
            residual = v * run.scale / (run.damping * umax.max(Real::MIN_POSITIVE));
            if steps >= min_steps && residual < run.tol {
                break;
            }
        }
    }
    let seconds = start.elapsed().as_secs_f64();
    let b = world.body(id)?;
    let rows = (0..b.particle_count())
        .map(|i| {
            (
                node_id(&run.scene, &mesh, b.particle_order().mesh_index(i)),
                (b.positions()[i] - b.rest_positions()[i])
                    / (run.scale * run.scale * load_factor(&run.scene)),
            )
        })
        .collect();
    Ok(StaticResult {
        rows,
        substeps,
        steps,
        residual,
        max_u: b.max_displacement() / (run.scale * run.scale * load_factor(&run.scene)),
        volume_ratio: b.volume_ratio(),
        fixed,
        seconds,
        converged: residual < run.tol,
    })
}

/// Write `node,ux,uy,uz`.
fn write_displacements(path: &Path, rows: &[(usize, Vec3)]) -> Res<()> {
    let mut sorted = rows.to_vec();
    sorted.sort_by_key(|r| r.0);
    let mut f = create(path)?;
    writeln!(f, "node,ux,uy,uz")?;
    for (n, u) in sorted {
        writeln!(f, "{n},{:.10e},{:.10e},{:.10e}", u.x, u.y, u.z)?;
    }
    Ok(())
}

const RUNS_HEADER: &str = "name,scene,volume_constraints,neighbours,hourglass,iterations,dt,\
damping_mass,substeps,steps,sim_time,residual,converged,max_u,volume_ratio,fixed,wall_s,csv";

fn runs_row(name: &str, run: &StaticRun, r: &StaticResult, csv: &str) -> String {
    format!(
        "{name},{},{},{},{},{},{},{},{},{},{:.4},{:.3e},{},{:.6e},{:.8},{},{:.2},{csv}",
        run.scene,
        run.volume_constraints,
        run.neighbours,
        run.hourglass,
        run.iterations,
        run.dt,
        run.damping,
        r.substeps,
        r.steps,
        r.steps as Real * run.dt,
        r.residual,
        r.converged,
        r.max_u,
        r.volume_ratio,
        r.fixed,
        r.seconds
    )
}

/// `static`: one run, its CSV, its summary on stdout.
pub fn static_command(args: &Args) -> Res<()> {
    let run = StaticRun::from_args(args)?;
    let r = run_static(&run)?;
    let out = args.string("out", "");
    if !out.is_empty() {
        write_displacements(Path::new(&out), &r.rows)?;
    }
    println!("{RUNS_HEADER}");
    println!("{}", runs_row("static", &run, &r, &out));
    Ok(())
}

/// `accuracy`: every static run of docs/VALIDATION.md into `--out DIR` (default
/// build/evidence/accuracy), with `DIR/runs.csv` listing them.
pub fn accuracy_command(args: &Args) -> Res<()> {
    let dir = PathBuf::from(args.string("out", "build/evidence/accuracy"));
    std::fs::create_dir_all(&dir)?;
    let only = args.string("only", "");
    let mut runs: Vec<(String, StaticRun)> = Vec::new();
    for scene in ["cantilever", "liver030", "liver045"] {
        for vol in [true, false] {
            let mut r = StaticRun::defaults(scene);
            r.volume_constraints = vol;
            let tag = if vol { "vol" } else { "novol" };
            runs.push((format!("{scene}_{tag}"), r));
        }
    }
    let variant = |scene: &str, name: &str, edit: &dyn Fn(&mut StaticRun)| {
        let mut r = StaticRun::defaults(scene);
        edit(&mut r);
        (format!("{scene}_{name}"), r)
    };
    for n in [12, 16, 24, 32] {
        runs.push(variant("liver030", &format!("vol_nb{n}"), &|r| {
            r.neighbours = n
        }));
    }
    for c in [0.0, 0.2, 0.5, 1.0, 2.0, 5.0] {
        runs.push(variant("liver030", &format!("vol_hg{c}"), &|r| {
            r.hourglass = c
        }));
    }
    for c in [0.5, 2.0, 5.0] {
        runs.push(variant("liver045", &format!("vol_hg{c}"), &|r| {
            r.hourglass = c
        }));
        runs.push(variant("cantilever", &format!("vol_hg{c}"), &|r| {
            r.hourglass = c
        }));
    }
    runs.push(variant("liver030", "novol_hg2", &|r| {
        r.volume_constraints = false;
        r.hourglass = 2.0;
    }));
    // Checks of the method, not of the material: XPBD iterations and unit independence.
    runs.push(variant("liver030", "vol_it4", &|r| r.iterations = 4));
    runs.push(variant("liver045", "vol_it4", &|r| r.iterations = 4));
    runs.push(variant("liver030", "vol_scale0.03", &|r| r.scale = 0.03));
    let mut table = create(&dir.join("runs.csv"))?;
    writeln!(table, "{RUNS_HEADER}")?;
    println!("{RUNS_HEADER}");
    for (name, run) in &runs {
        if !only.is_empty() && !name.contains(&only) {
            continue;
        }
        let r = run_static(run)?;
        let csv = format!("{name}.csv");
        write_displacements(&dir.join(&csv), &r.rows)?;
        let row = runs_row(name, run, &r, &csv);
        println!("{row}");
        writeln!(table, "{row}")?;
        table.flush()?;
    }
    Ok(())
}
