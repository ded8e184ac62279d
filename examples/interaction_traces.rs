//! Force traces of the surgical interactions on the default organ (hanging from its top 15%,
//! settled at rest first), written as CSV for `validation/plot_interaction.py`:
//!
//! - `needle_trace.csv`: a 1 mm capsule needle pushed 4 cm into the organ's front face at
//!   2 cm/s, held 0.2 s, pulled back out at 2 cm/s (puncture force 0.3 N, friction 10 N/m);
//! - `grasp_trace.csv`: a 5 mm sphere pressed 4 mm into the front face, grasping, pulled 3 cm
//!   out at 2 cm/s, held 0.3 s, released, withdrawn;
//! - `press_trace_r{10,2.5,1}mm.csv`: spheres of radius 10, 2.5 and 1 mm pressed horizontally
//!   into the front face at 5 cm/s until they are 3 cm past it; a summary line per radius on
//!   stdout (steps with the centre inside the deformed surface, force at 1/2/3 cm, the force's
//!   mean rise per step and its step-to-step jitter, the second difference, median and p99).
//!
//! ```text
//! cargo run --release --example interaction_traces -- [OUT_DIR]    # default docs/data
//! ```
//! Columns: time (s), tool travel (m, along the motion), force along the motion (N, the
//! tissue's force on the tool projected on the direction of travel into the organ), |F| (N),
//! then needle: punctured (0/1), inserted length (m), held particles; grasp: grasped particles;
//! press: depth of the sphere's front past first contact (the contact skin over the undeformed
//! face, m), centre inside (0/1).

use std::fmt::Write as _;
use std::path::PathBuf;
use tissuesim::{
    mesh, BodyId, BodyOptions, GraspOptions, NeedleOptions, Pose, Quat, Real, Settings, ToolId,
    ToolOptions, ToolShape, Vec3, World,
};

type Res<T> = Result<T, Box<dyn std::error::Error>>;

/// The default organ hanging from its top 15%, settled, its body, and the front face's z (m) at
/// (x, y) = (0.035, 0), found as the largest particle z near that line.
fn organ() -> Res<(World, BodyId, Real)> {
    let organ = mesh::default_organ();
    let (lo, hi) = organ.bounding_box();
    let mut world = World::new(Settings::default())?;
    let body = world.add_body(&organ, &BodyOptions::default())?;
    let top = hi.y - 0.15 * (hi.y - lo.y);
    world.fix_box(
        body,
        Vec3::new(lo.x - 1.0, top, lo.z - 1.0),
        Vec3::new(hi.x + 1.0, hi.y + 1.0, hi.z + 1.0),
    )?;
    world.settle()?;
    let face = world
        .body(body)?
        .positions()
        .iter()
        .filter(|p| (p.x - 0.035).abs() < 0.01 && p.y.abs() < 0.01)
        .map(|p| p.z)
        .fold(Real::NEG_INFINITY, Real::max);
    Ok((world, body, face))
}

/// Move `tool` to `pose`, step, and return (force along `into` N, |F| N).
fn step(world: &mut World, tool: ToolId, pose: Pose, into: Vec3) -> Res<(Real, Real)> {
    world.set_tool_pose(tool, pose)?;
    world.step()?;
    let f = world.tool(tool)?.wrench().force;
    Ok((-f.dot(&into), f.norm()))
}

fn needle_trace() -> Res<String> {
    let (mut world, _, face) = organ()?;
    let dt = world.settings().dt;
    let (half, radius) = (0.05, 0.001);
    // Shaft along -z (into the front face): local +y turned onto -z.
    let orientation = Quat::from_axis_angle(&Vec3::x_axis(), -std::f64::consts::FRAC_PI_2);
    let into = -Vec3::z();
    let start_tip = Vec3::new(0.035, 0.0, face + 0.012);
    let pose = |travel: Real| Pose {
        position: start_tip + into * travel - into * (half + radius),
        orientation,
    };
    let tool = world.add_tool(
        ToolShape::Capsule {
            half_height: half,
            radius,
        },
        pose(0.0),
        &ToolOptions::default(),
    )?;
    let options = NeedleOptions {
        puncture_force: 0.3,
        friction_per_length: 10.0,
        reach: None,
    };
    world.make_needle(tool, &options)?;
    let speed = 0.02;
    let depth = 0.012 + 0.04;
    let t_in = depth / speed;
    let (t_hold, t_out) = (t_in + 0.2, 2.0 * t_in + 0.2);
    let mut csv = String::from(
        "time_s,travel_m,force_along_n,force_norm_n,punctured,inserted_length_m,held\n",
    );
    let steps = (t_out / dt).round() as usize;
    for k in 1..=steps {
        let t = k as Real * dt;
        let travel = if t <= t_in {
            speed * t
        } else if t <= t_hold {
            depth
        } else {
            depth - speed * (t - t_hold)
        };
        let (along, norm) = step(&mut world, tool, pose(travel), into)?;
        let s = world.needle_state(tool)?;
        writeln!(
            csv,
            "{t:.4},{travel:.6},{along:.6},{norm:.6},{},{:.6},{}",
            s.punctured as u8, s.inserted_length, s.held
        )?;
    }
    Ok(csv)
}

fn grasp_trace() -> Res<String> {
    let (mut world, body, face) = organ()?;
    let dt = world.settings().dt;
    let radius = 0.005;
    let into = -Vec3::z();
    let r = world.body(body)?.particle_radius();
    // The sphere's surface starts one particle radius off the face (just touching the particles).
    let start = Vec3::new(0.035, 0.0, face + r + radius);
    let tool = world.add_tool(
        ToolShape::Sphere { radius },
        Pose::at(start),
        &ToolOptions::default(),
    )?;
    let speed = 0.02;
    let (press, pull) = (0.004, 0.03);
    let t_press = press / speed;
    let t_grasp = t_press + 0.1;
    let t_pull = t_grasp + (press + pull) / speed;
    let t_hold = t_pull + 0.3;
    let t_end = t_hold + 0.3;
    let mut csv = String::from("time_s,travel_m,force_along_n,force_norm_n,grasped\n");
    let mut grasped = false;
    let mut released = false;
    let steps = (t_end / dt).round() as usize;
    for k in 1..=steps {
        let t = k as Real * dt;
        let travel = if t <= t_press {
            speed * t
        } else if t <= t_grasp {
            press
        } else if t <= t_pull {
            press - speed * (t - t_grasp)
        } else if t <= t_hold {
            -pull
        } else {
            -pull - speed * (t - t_hold)
        };
        if t > t_press + 0.05 && !grasped {
            world.grasp(tool, &GraspOptions::default())?;
            grasped = true;
        }
        if t > t_hold && !released {
            world.release(tool)?;
            released = true;
        }
        let (along, norm) = step(&mut world, tool, Pose::at(start + into * travel), into)?;
        let held = world.grasped_count(tool)?;
        writeln!(csv, "{t:.4},{travel:.6},{along:.6},{norm:.6},{held}")?;
    }
    Ok(csv)
}

/// Press a sphere of `radius` (m) into the front face at 5 cm/s until its front is 3 cm past
/// first contact; returns the CSV trace and a one-line summary.
fn press_trace(radius: Real) -> Res<(String, String)> {
    let (mut world, body, face) = organ()?;
    let dt = world.settings().dt;
    let into = -Vec3::z();
    // Start 2 mm clear of the contact skin; depth counts from the skin.
    let gap = 0.002;
    let skin = world.body(body)?.contact_skin();
    let start = Vec3::new(0.035, 0.0, face + skin + gap + radius);
    let tool = world.add_tool(
        ToolShape::Sphere { radius },
        Pose::at(start),
        &ToolOptions::default(),
    )?;
    let (speed, press) = (0.05, 0.03);
    let steps = ((gap + press) / speed / dt).round() as usize;
    let mut csv = String::from("time_s,travel_m,depth_m,force_along_n,force_norm_n,inside\n");
    let (mut inside_steps, mut in_contact) = (0, Vec::new());
    let mut at_depth = [Real::NAN; 3];
    for k in 1..=steps {
        let t = k as Real * dt;
        let travel = speed * t;
        let depth = travel - gap;
        let centre = start + into * travel;
        let (along, norm) = step(&mut world, tool, Pose::at(centre), into)?;
        let inside = world.body(body)?.contains(&centre);
        inside_steps += inside as usize;
        if depth > 0.0 {
            in_contact.push(along);
        }
        for (cm, slot) in at_depth.iter_mut().enumerate() {
            if slot.is_nan() && depth >= 0.01 * (cm + 1) as Real - 1e-9 {
                *slot = along;
            }
        }
        writeln!(
            csv,
            "{t:.4},{travel:.6},{depth:.6},{along:.6},{norm:.6},{}",
            inside as u8
        )?;
    }
    // Jitter: the second difference F[k+1] − 2 F[k] + F[k−1] (N), zero for a smooth ramp.
    let mut jitter: Vec<Real> = in_contact
        .windows(3)
        .map(|f| (f[2] - 2.0 * f[1] + f[0]).abs())
        .collect();
    jitter.sort_by(Real::total_cmp);
    let quantile = |q: Real| jitter[((jitter.len() - 1) as Real * q).round() as usize];
    let ramp = (in_contact[in_contact.len() - 1] - in_contact[0]) / (in_contact.len() - 1) as Real;
    let summary = format!(
        "sphere r = {:.1} mm: centre inside on {inside_steps} of {steps} steps; force at 1/2/3 cm \
         {:.3}/{:.3}/{:.3} N; mean rise {ramp:.2e} N/step, jitter |F[k+1] - 2F[k] + F[k-1]| \
         median {:.2e} N, p99 {:.2e} N",
        radius * 1e3,
        at_depth[0],
        at_depth[1],
        at_depth[2],
        quantile(0.5),
        quantile(0.99)
    );
    Ok((csv, summary))
}

fn main() -> Res<()> {
    let out = std::env::args()
        .nth(1)
        .map(PathBuf::from)
        .unwrap_or_else(|| PathBuf::from(concat!(env!("CARGO_MANIFEST_DIR"), "/docs/data")));
    std::fs::create_dir_all(&out)?;
    for (name, csv) in [
        ("needle_trace.csv", needle_trace()?),
        ("grasp_trace.csv", grasp_trace()?),
    ] {
        let path = out.join(name);
        std::fs::write(&path, csv)?;
        println!("wrote {}", path.display());
    }
    for (radius, name) in [
        (0.010, "press_trace_r10mm.csv"),
        (0.0025, "press_trace_r2.5mm.csv"),
        (0.001, "press_trace_r1mm.csv"),
    ] {
        let (csv, summary) = press_trace(radius)?;
        let path = out.join(name);
        std::fs::write(&path, csv)?;
        println!("wrote {}: {summary}", path.display());
    }
    Ok(())
}
