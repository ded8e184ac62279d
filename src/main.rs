//! The main job: the embedded default organ, its top fixed, hanging under gravity. It starts
//! from its equilibrium (`World::settle`), so it hangs at rest from the first step;
//! `--no-settle` starts it from the rest shape instead, to watch it sag and swing.
//!
//! ```text
//! cargo run --release -- [--steps N] [--out DIR] [--every K] [--no-settle]
//! ```
//! Prints time (s), largest displacement (mm), volume ratio and ms per step as it runs, and writes
//! `DIR/organ_XXXX.vtu` every K steps (default `out/`, every 100 steps) for ParaView, and beside
//! it `DIR/organ_XXXX_surface.obj`: the organ's render surface (its boundary triangles, which the
//! default organ has instead of a visual mesh) with per-vertex normals, for a renderer.

use std::path::PathBuf;
use std::time::Instant;
use tissuesim::render::RenderMesh;
use tissuesim::{mesh, BodyOptions, Settings, Vec3, World};

struct Args {
    steps: usize,
    settle: bool,
    out: PathBuf,
    every: usize,
}

fn parse_args() -> Result<Args, String> {
    let mut args = Args {
        steps: 2000,
        settle: true,
        out: PathBuf::from("out"),
        every: 100,
    };
    let mut it = std::env::args().skip(1);
    while let Some(a) = it.next() {
        let mut value = |name: &str| it.next().ok_or(format!("{name} needs a value"));
        match a.as_str() {
            "--no-settle" => args.settle = false,
            "--steps" => args.steps = value("--steps")?.parse().map_err(|e| format!("{e}"))?,
            "--every" => args.every = value("--every")?.parse().map_err(|e| format!("{e}"))?,
            "--out" => args.out = PathBuf::from(value("--out")?),
            "-h" | "--help" => {
                return Err(
                    "usage: tissuesim [--steps N] [--out DIR] [--every K] [--no-settle]".into(),
                )
            }
            other => return Err(format!("unknown argument {other}")),
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

fn run(args: &Args) -> Result<(), Box<dyn std::error::Error>> {
    let organ = mesh::default_organ();
    let (lo, hi) = organ.bounding_box();
    let mut world = World::new(Settings::default())?;
    let body = world.add_body(&organ, &BodyOptions::default())?;
    // Fix the top 15% of the organ (its ligaments), let the rest sag under gravity.
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
    println!(
        "{:>8} {:>12} {:>14} {:>12} {:>10}",
        "t (s)", "max |u| (mm)", "max |v| (mm/s)", "volume ratio", "ms/step"
    );
    let mut elapsed = 0.0;
    for s in 1..=args.steps {
        let t0 = Instant::now();
        world.step()?;
        elapsed += t0.elapsed().as_secs_f64();
        if s % args.every == 0 || s == args.steps {
            let b = world.body(body)?;
            let speed = b.velocities().iter().map(|v| v.norm()).fold(0.0, f64::max);
            println!(
                "{:8.3} {:12.3} {:14.3} {:12.6} {:10.3}",
                world.time(),
                b.max_displacement() * 1e3,
                speed * 1e3,
                b.volume_ratio(),
                elapsed * 1e3 / s as f64
            );
            let displacement: Vec<Vec3> = b
                .positions()
                .iter()
                .zip(b.rest_positions())
                .map(|(x, r)| x - r)
                .collect();
            let path = args.out.join(format!("organ_{:04}.vtu", s / args.every));
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
            world.update_render_surface(surface)?.write_obj(
                &path.with_file_name(format!("organ_{:04}_surface.obj", s / args.every)),
            )?;
        }
    }
    println!(
        "VTU files and render surfaces (OBJ) in {}",
        args.out.display()
    );
    Ok(())
}
