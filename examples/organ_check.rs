//! Diagnostic for docs/history/VALIDATION_HISTORY.md §1.4: the gravity sag of the project's own quasi-uniform
//! default organ (scaled ×30 to liver size, mesh units), the liver scene's material (E 3000,
//! ν 0.3, ρ 1, g 0.981, top 10% fixed), compared with scikit-fem by `validation/organ_check.sh`.
//!
//! ```text
//! cargo run --release --example organ_check -- export DIR [CELL]   # DIR/organ.node, .ele
//! cargo run --release --example organ_check -- run CSV [HOURGLASS]  # node,ux,uy,uz at equilibrium
//! ```
//!
//! `export` writes the organ of `tissuesim::mesh::organ_with_cell(CELL)` (lattice cell edge in m,
//! default 0.0095 = the default organ), scaled ×30 like `run`; `validation/fem_reference.py
//! --scene organ` solves it at CELL = 0.0133, 0.0095 and 0.0068.

use std::io::Write;
use std::path::Path;
use tissuesim::{BodyOptions, Material, Settings, Vec3, World};

type Res<T> = Result<T, Box<dyn std::error::Error>>;

fn main() -> Res<()> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let scaled = |mut organ: tissuesim::mesh::TetMesh| {
        for p in &mut organ.nodes {
            *p *= 30.0;
        }
        organ
    };
    match args.first().map(String::as_str) {
        Some("export") => {
            let dir = Path::new(args.get(1).ok_or("export DIR [CELL]")?);
            let cell: f64 = match args.get(2) {
                Some(c) => c.parse()?,
                None => 0.0095,
            };
            let organ = scaled(tissuesim::mesh::organ_with_cell(cell));
            std::fs::create_dir_all(dir)?;
            let mut f = std::fs::File::create(dir.join("organ.node"))?;
            writeln!(f, "{} 3 0 0", organ.nodes.len())?;
            for (i, p) in organ.nodes.iter().enumerate() {
                writeln!(f, "{i} {:.17e} {:.17e} {:.17e}", p.x, p.y, p.z)?;
            }
            let mut f = std::fs::File::create(dir.join("organ.ele"))?;
            writeln!(f, "{} 4 0", organ.tets.len())?;
            for (i, t) in organ.tets.iter().enumerate() {
                writeln!(f, "{i} {} {} {} {}", t[0], t[1], t[2], t[3])?;
            }
            Ok(())
        }
        Some("run") => {
            let out = args.get(1).ok_or("run CSV [HOURGLASS]")?;
            let hourglass = match args.get(2) {
                Some(h) => h.parse()?,
                None => Settings::default().hourglass_stiffness,
            };
            run(
                &scaled(tissuesim::mesh::default_organ()),
                Path::new(out),
                hourglass,
            )
        }
        _ => Err("usage: organ_check export DIR [CELL] | run CSV [HOURGLASS]".into()),
    }
}

fn run(organ: &tissuesim::mesh::TetMesh, out: &Path, hourglass: f64) -> Res<()> {
    let settings = Settings {
        dt: 0.002,
        gravity: Vec3::new(0.0, -0.981, 0.0),
        damping_mass: 15.0,
        hourglass_stiffness: hourglass,
        ..Settings::default()
    };
    let mut world = World::new(settings)?;
    let material = Material {
        youngs_modulus: 3000.0,
        poisson_ratio: 0.3,
        density: 1.0,
    };
    let options = BodyOptions {
        material,
        ..BodyOptions::default()
    };
    let id = world.add_body(organ, &options)?;
    let (lo, hi) = organ.bounding_box();
    let threshold = hi.y - 0.1 * (hi.y - lo.y);
    let fixed: Vec<u32> = (0..organ.nodes.len() as u32)
        .filter(|&k| organ.nodes[k as usize].y >= threshold)
        .collect();
    let particles = world.body(id)?.particle_order().particles_of(&fixed);
    world.fix_particles(id, &particles.ok_or("fixed node out of range")?)?;
    for _ in 0..8000 {
        world.step()?;
    }
    let b = world.body(id)?;
    let speed = b.velocities().iter().map(|v| v.norm()).fold(0.0, f64::max);
    eprintln!(
        "organ_check: {} fixed, hourglass {hourglass}, max |u| {:.4e}, residual speed {speed:.1e}",
        fixed.len(),
        b.max_displacement()
    );
    let mut f = std::fs::File::create(out)?;
    writeln!(f, "node,ux,uy,uz")?;
    let order = b.particle_order();
    for k in 0..b.particle_count() {
        let i = order.particle(k);
        let u = b.positions()[i] - b.rest_positions()[i];
        writeln!(f, "{k},{:.17e},{:.17e},{:.17e}", u.x, u.y, u.z)?;
    }
    Ok(())
}
