//! Issue #3: the force trace of a 1 cm sphere probe pressed horizontally 2 cm into the DESIGN §7
//! liver and released, in both contact modes.

use crate::common::{create, design_scene, Res};
use crate::experiments::add_probe;
use crate::Args;
use std::io::Write;
use std::path::PathBuf;
use tissuesim::{ContactMode, Pose, Real, Settings, Vec3};

/// `press`: `--out CSV` (default docs/data/press_trace.csv), `--depth` (m, 0.02), `--in`,
/// `--hold`, `--outtime` (s: 1, 0.5, 1), `--after` (s, 0.5), `--settle` (s, 2: the organ sags to rest under gravity first, with strong damping).
pub fn press_command(args: &Args) -> Res<()> {
    let out = PathBuf::from(args.string("out", "docs/data/press_trace.csv"));
    let depth: Real = args.get("depth", 0.02)?;
    let t_in: Real = args.get("in", 1.0)?;
    let t_hold: Real = args.get("hold", 0.5)?;
    let t_out: Real = args.get("outtime", 1.0)?;
    let t_after: Real = args.get("after", 0.5)?;
    let t_settle: Real = args.get("settle", 2.0)?;
    let mut f = create(&out)?;
    writeln!(
        f,
        "mode,time,depth,fx,fy,fz,f,contact_count,volume_ratio,max_penetration"
    )?;
    for (name, mode) in [
        ("exact", ContactMode::ExactShape),
        ("sampled", ContactMode::SampledPoints),
    ] {
        let settings = Settings {
            contact_mode: mode,
            ..Settings::default()
        };
        let (mut world, id) = design_scene("liver_4k", settings)?;
        let dt = world.settings().dt;
        crate::experiments::settle(&mut world, t_settle)?;
        let settle_speed = crate::common::max_speed(&world, id)?;
        let (tool, contact, thick) = add_probe(&mut world, id)?;
        let dir = Vec3::new(0.0, 0.0, -1.0);
        let total = t_in + t_hold + t_out + t_after;
        let steps = (total / dt).round() as usize;
        let mut peak: Real = 0.0;
        for k in 1..=steps {
            let t = k as Real * dt;
            let d = if t < t_in {
                depth * t / t_in
            } else if t < t_in + t_hold {
                depth
            } else if t < t_in + t_hold + t_out {
                depth * (1.0 - (t - t_in - t_hold) / t_out)
            } else {
                0.0
            };
            world.set_tool_pose(tool, Pose::at(contact + dir * d))?;
            world.step()?;
            let w = world.tool(tool)?.wrench();
            let fv = w.force;
            peak = peak.max(fv.norm());
            writeln!(
                f,
                "{name},{t:.4},{d:.6},{:.6e},{:.6e},{:.6e},{:.6e},{},{:.8},{:.4e}",
                fv.x,
                fv.y,
                fv.z,
                fv.norm(),
                w.contact_count,
                world.body(id)?.volume_ratio(),
                w.max_penetration
            )?;
        }
        eprintln!(
            "{name}: largest speed after settling {settle_speed:.2e} m/s, thickness {thick:.4} m, \
             contact at z = {:.4} m, peak |f| {peak:.4} N, substeps {}",
            contact.z,
            world.substeps_needed().0
        );
    }
    Ok(())
}
