//! The main job: what the library does, on the embedded default organ hanging from its fixed
//! top. It starts from its equilibrium (`World::settle`), then runs a scripted scenario:
//!
//! 1. a 5 mm sphere presses 2 cm into the organ's front at 5 cm/s, holds 0.2 s, withdraws;
//! 2. a grasper (a 4 mm sphere) comes up under the lowest point, grasps, lifts the tissue 2 cm,
//!    holds it, lets go, and the organ swings back;
//! 3. a blade (a thin capsule spanning the organ's width) sweeps from front to back at 1 m/s,
//!    3 cm above the lowest point, and the organ runs on for 0.5 s: the last line says how many
//!    particles ended more than 5 cm below the organ's lowest point before the cut.
//!
//! ```text
//! cargo run --release -- [--out DIR] [--every K] [--no-settle]
//! ```
//! Prints, every 50 steps, the time (s), the phase, the force of the tissue on the active tool
//! (N), its contacts or grasped particles, the largest displacement (mm) and the volume ratio,
//! and writes `DIR/organ_XXXX.vtu` every K steps (default `out/`, every 25 steps) for ParaView,
//! and beside it `DIR/organ_XXXX_surface.obj`: the organ's render surface (its boundary
//! triangles, which the default organ has instead of a visual mesh) with per-vertex normals.

use std::path::PathBuf;
use std::time::Instant;
use tissuesim::render::RenderMesh;
use tissuesim::{
    mesh, BodyId, BodyOptions, GraspOptions, Pose, Quat, Real, RenderSurfaceId, Settings, ToolId,
    ToolOptions, ToolShape, Vec3, World,
};

/// What `--help` prints (stdout, exit 0) and an unknown argument shows (stderr, exit 2).
const USAGE: &str = "usage: tissuesim [--out DIR] [--every K] [--no-settle]
  Settles the default organ, then presses a probe, grasps and lifts, and cuts it, printing the
  tool forces (N) as it runs.
  --out DIR     where the VTU/OBJ frames go (default: out)
  --every K     write a frame every K steps of 1 ms (default: 25)
  --no-settle   start from the rest shape instead of the static equilibrium under gravity";

struct Args {
    settle: bool,
    out: PathBuf,
    every: usize,
}

fn parse_args() -> Result<Args, String> {
    let mut args = Args {
        settle: true,
        out: PathBuf::from("out"),
        every: 25,
    };
    let mut it = std::env::args().skip(1);
    while let Some(a) = it.next() {
        let mut value = |name: &str| it.next().ok_or(format!("{name} needs a value"));
        match a.as_str() {
            "--no-settle" => args.settle = false,
            "--every" => args.every = value("--every")?.parse().map_err(|e| format!("{e}"))?,
            "--out" => args.out = PathBuf::from(value("--out")?),
            "-h" | "--help" => {
                println!("{USAGE}");
                std::process::exit(0);
            }
            other => return Err(format!("unknown argument {other}\n{USAGE}")),
        }
    }
    if args.every == 0 {
        return Err("--every must be >= 1".into());
    }
    Ok(args)
}

fn main() {
    let args = match parse_args() {
        Ok(a) => a,
        Err(e) => {
            eprintln!("{e}");
            std::process::exit(2);
        }
    };
    if let Err(e) = run(&args) {
        eprintln!("error: {e}");
        std::process::exit(1);
    }
}

/// Where a tool waits while another one works (m): far from the organ.
const PARKED: Vec3 = Vec3::new(0.0, -1.0, 0.0);

/// The scene as it runs: the world, its organ and render surface, the output, the step count.
struct Scene<'a> {
    world: World,
    body: BodyId,
    surface: RenderSurfaceId,
    args: &'a Args,
    steps: usize,
    step_seconds: Real,
    /// Tetrahedra and neighbour pairs cut so far.
    cut_tets: usize,
    cut_pairs: usize,
}

impl Scene<'_> {
    /// Step once with `tool` moved to `pose`; print a line every 50 steps and write a frame
    /// every `--every` steps.
    fn step(
        &mut self,
        phase: &str,
        tool: ToolId,
        pose: Pose,
    ) -> Result<(), Box<dyn std::error::Error>> {
        self.world.set_tool_pose(tool, pose)?;
        let t0 = Instant::now();
        let report = self.world.step()?;
        self.step_seconds += t0.elapsed().as_secs_f64();
        self.steps += 1;
        self.cut_tets += report.cut.tets;
        self.cut_pairs += report.cut.pairs;
        if self.steps.is_multiple_of(50) {
            let w = self.world.tool(tool)?.wrench();
            let held = self.world.grasped_count(tool)?;
            let b = self.world.body(self.body)?;
            println!(
                "{:8.3}  {phase:<8} {:>7.3} {:>7.3} {:>7.3} {:>9} {:>12.2} {:>10.5}",
                self.world.time(),
                w.force.x,
                w.force.y,
                w.force.z,
                if held > 0 {
                    held
                } else {
                    w.contact_count as usize
                },
                b.max_displacement() * 1e3,
                b.volume_ratio(),
            );
        }
        if self.steps.is_multiple_of(self.args.every) {
            self.write_frame(self.steps / self.args.every)?;
        }
        Ok(())
    }

    /// Write frame `k`: the organ as VTU and its render surface as OBJ.
    fn write_frame(&mut self, k: usize) -> Result<(), Box<dyn std::error::Error>> {
        let b = self.world.body(self.body)?;
        let displacement: Vec<Vec3> = (b.positions().iter().zip(b.rest_positions()))
            .map(|(x, r)| x - r)
            .collect();
        let path = self.args.out.join(format!("organ_{k:04}.vtu"));
        mesh::write_vtu(
            &path,
            b.positions(),
            b.tets(),
            &[],
            &[
                ("displacement", &displacement),
                ("velocity", b.velocities()),
            ],
        )?;
        self.world
            .update_render_surface(self.surface)?
            .write_obj(&path.with_file_name(format!("organ_{k:04}_surface.obj")))?;
        Ok(())
    }

    /// Move `tool` from `from` to `to` (m) at `speed` (m/s), with `orientation`.
    fn travel(
        &mut self,
        phase: &str,
        tool: ToolId,
        (from, to): (Vec3, Vec3),
        speed: Real,
        orientation: Quat,
    ) -> Result<(), Box<dyn std::error::Error>> {
        let dt = self.world.settings().dt;
        let steps = ((to - from).norm() / speed / dt).ceil().max(1.0) as usize;
        for k in 1..=steps {
            let position = from + (to - from) * (k as Real / steps as Real);
            self.step(
                phase,
                tool,
                Pose {
                    position,
                    orientation,
                },
            )?;
        }
        Ok(())
    }

    /// Keep `tool` at `position` (m) for `seconds` (s).
    fn hold(
        &mut self,
        phase: &str,
        tool: ToolId,
        position: Vec3,
        seconds: Real,
    ) -> Result<(), Box<dyn std::error::Error>> {
        let steps = (seconds / self.world.settings().dt).round() as usize;
        for _ in 0..steps {
            self.step(phase, tool, Pose::at(position))?;
        }
        Ok(())
    }

    /// The organ's current particles within `radius` (m) of the line through `point` along the
    /// unit `direction`, as their coordinates along it (m).
    fn along_line(&self, point: Vec3, direction: Vec3, radius: Real) -> Vec<Real> {
        let b = self.world.body(self.body).expect("the organ");
        b.positions()
            .iter()
            .map(|p| p - point)
            .filter(|q| (q - direction * q.dot(&direction)).norm() < radius)
            .map(|q| q.dot(&direction))
            .collect()
    }
}

fn run(args: &Args) -> Result<(), Box<dyn std::error::Error>> {
    let organ = mesh::default_organ();
    let (lo, hi) = organ.bounding_box();
    let mut world = World::new(Settings::default())?;
    let body = world.add_body(&organ, &BodyOptions::default())?;
    // Fix the top 15% of the organ (its ligaments), let the rest hang under gravity.
    let top = hi.y - 0.15 * (hi.y - lo.y);
    let fixed = world.fix_box(
        body,
        Vec3::new(lo.x - 1.0, top, lo.z - 1.0),
        Vec3::new(hi.x + 1.0, hi.y + 1.0, hi.z + 1.0),
    )?;
    let b = world.body(body)?;
    let surface = RenderMesh::from_boundary(b.rest_positions(), b.boundary_triangles());
    let surface = world.add_render_surface(body, surface)?;
    let b = world.body(body)?;
    println!(
        "default organ: {} particles, {} tetrahedra, {} fixed, {:.3} kg, {:.1} cm3, size {:.0} mm",
        b.particle_count(),
        b.tets().len(),
        fixed,
        b.mass(),
        b.rest_volume() * 1e6,
        (hi - lo).max() * 1e3
    );
    if args.settle {
        let t0 = Instant::now();
        let report = world.settle()?;
        println!(
            "settle: {} in {:.2} s ({} Newton iterations, residual {:.1e} of the weight; {} relaxation steps, max speed {:.1e} m/s)",
            if report.converged { "at rest" } else { "NOT at rest" },
            t0.elapsed().as_secs_f64(),
            report.newton_iterations,
            report.relative_residual,
            report.relaxation_steps,
            report.max_speed
        );
    }
    std::fs::create_dir_all(&args.out)?;
    let skin = world.body(body)?.contact_skin();
    let mut scene = Scene {
        world,
        body,
        surface,
        args,
        steps: 0,
        step_seconds: 0.0,
        cut_tets: 0,
        cut_pairs: 0,
    };
    scene.write_frame(0)?;
    println!(
        "{:>8}  {:<8} {:>7} {:>7} {:>7} {:>9} {:>12} {:>10}",
        "t (s)", "phase", "Fx (N)", "Fy (N)", "Fz (N)", "contacts", "max|u| (mm)", "volume"
    );
    let none = Quat::identity();

    // 1. Press: a 5 mm sphere into the front (+z face) of the right lobe, 2 cm past contact.
    let radius = 0.005;
    let through = Vec3::new(0.035, 0.0, 0.0);
    let front = scene
        .along_line(through, Vec3::z(), 0.01)
        .into_iter()
        .fold(Real::NEG_INFINITY, Real::max);
    let start = through + Vec3::z() * (front + skin + radius + 0.002);
    let deepest = start - Vec3::z() * 0.022;
    let options = ToolOptions::default();
    let probe = scene
        .world
        .add_tool(ToolShape::Sphere { radius }, Pose::at(start), &options)?;
    scene.travel("press", probe, (start, deepest), 0.05, none)?;
    scene.hold("hold", probe, deepest, 0.2)?;
    scene.travel("release", probe, (deepest, start), 0.05, none)?;
    scene.world.remove_tool(probe)?;

    // 2. Grasp: a 4 mm sphere up to the lowest point, grasp, lift 2 cm, hold, let go.
    let radius = 0.004;
    let b = scene.world.body(body)?;
    let lowest = *b
        .positions()
        .iter()
        .min_by(|p, q| p.y.total_cmp(&q.y))
        .expect("the organ has particles");
    let below = lowest - Vec3::y() * (radius + skin + 0.005);
    let touching = lowest - Vec3::y() * radius;
    let grasper = scene
        .world
        .add_tool(ToolShape::Sphere { radius }, Pose::at(below), &options)?;
    scene.travel("approach", grasper, (below, touching), 0.05, none)?;
    let held = scene.world.grasp(grasper, &GraspOptions::default())?;
    println!("{:8.3}  grasp    {held} particles held", scene.world.time());
    let lifted = touching + Vec3::y() * 0.02;
    scene.travel("lift", grasper, (touching, lifted), 0.05, none)?;
    scene.hold("hold", grasper, lifted, 0.2)?;
    scene.world.release(grasper)?;
    println!("{:8.3}  release", scene.world.time());
    scene.hold("swing", grasper, PARKED, 0.3)?;
    scene.world.remove_tool(grasper)?;

    // 3. Cut: a blade spanning the organ's width (its edge along x) sweeps along −z from front
    //    to back, 3 cm above the lowest point; then 0.5 s more.
    let b = scene.world.body(body)?;
    let (lo, hi) = (
        b.positions()
            .iter()
            .fold(Vec3::repeat(Real::MAX), |a, p| a.inf(p)),
        b.positions()
            .iter()
            .fold(Vec3::repeat(Real::MIN), |a, p| a.sup(p)),
    );
    // A capsule's edge is its local y axis: a quarter turn about z lays it along x.
    let along_x = Quat::from_axis_angle(&Vec3::z_axis(), std::f64::consts::FRAC_PI_2);
    let blade_shape = ToolShape::Capsule {
        half_height: 0.5 * (hi.x - lo.x) + 0.05,
        radius: 0.0005,
    };
    let (x_mid, y_cut) = (0.5 * (lo.x + hi.x), lo.y + 0.03);
    let front = Vec3::new(x_mid, y_cut, hi.z + 0.03);
    let back = Vec3::new(x_mid, y_cut, lo.z - 0.03);
    let pose = Pose {
        position: front,
        orientation: along_x,
    };
    let blade = scene.world.add_tool(blade_shape, pose, &options)?;
    scene.world.make_blade(blade)?;
    let lowest_before = lo.y;
    scene.travel("cut", blade, (front, back), 1.0, along_x)?;
    println!(
        "{:8.3}  cut      {} tetrahedra and {} neighbour pairs cut",
        scene.world.time(),
        scene.cut_tets,
        scene.cut_pairs
    );
    let parked = Pose {
        position: PARKED,
        orientation: along_x,
    };
    for _ in 0..(0.5 / scene.world.settings().dt) as usize {
        scene.step("fall", blade, parked)?;
    }
    let b = scene.world.body(body)?;
    let lowest = b.positions().iter().map(|p| p.y).fold(Real::MAX, Real::min);
    let fallen = b
        .positions()
        .iter()
        .filter(|p| p.y < lowest_before - 0.05)
        .count();
    println!(
        "{:8.3}  fall     {fallen} particles more than 5 cm below where the organ ended; \
         lowest point {:.1} mm, was {:.1} mm before the cut",
        scene.world.time(),
        lowest * 1e3,
        lowest_before * 1e3
    );
    println!(
        "{} steps, {:.3} ms per step; VTU files and render surfaces (OBJ) in {}",
        scene.steps,
        scene.step_seconds * 1e3 / scene.steps as Real,
        args.out.display()
    );
    Ok(())
}
