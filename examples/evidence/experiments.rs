//! The paper's experiments (issue #6 item 2) on the DESIGN §7 scene: volume over time with and
//! without volume constraints (Fig. 6), runtime (Fig. 7), large deformations (Fig. 9).

use crate::common::{
    bounds, create, design_scene, inversion_stats, percentile, touch_distance, write_positions,
    write_triangles, write_vtu, Res,
};
use crate::Args;
use std::io::Write;
use std::path::{Path, PathBuf};
use std::time::Instant;
use tissuesim::{BodyId, Pose, Real, Settings, ToolId, ToolOptions, ToolShape, Vec3, World};

/// Probe radius (m).
const PROBE_RADIUS: Real = 0.01;
/// Horizontal press direction: from the front (+z) towards the back.
fn press_direction() -> Vec3 {
    Vec3::new(0.0, 0.0, -1.0)
}

fn settings(volume_constraints: bool) -> Settings {
    Settings {
        volume_constraints,
        ..Settings::default()
    }
}

/// Let the organ sag to rest under gravity for `seconds` with strong mass damping (20/s), then
/// restore the scene's settings: the probing experiments start from a settled organ.
pub fn settle(world: &mut World, seconds: Real) -> Res<()> {
    let original = world.settings().clone();
    world.set_settings(Settings {
        damping_mass: 20.0,
        ..original.clone()
    })?;
    for _ in 0..(seconds / original.dt).round() as usize {
        world.step()?;
    }
    world.set_settings(original)?;
    Ok(())
}

/// A probe placed just outside first contact on the horizontal line through the organ's
/// centroid (current positions) along the press direction; returns the tool, the touching
/// position of its centre and the organ's thickness along that line (extent of the particles
/// within 1 cm of the line).
pub fn add_probe(world: &mut World, id: BodyId) -> Res<(ToolId, Vec3, Real)> {
    let d = press_direction();
    let b = world.body(id)?;
    let pr = b.particle_radius();
    let x = b.positions();
    let centroid = x.iter().sum::<Vec3>() / x.len() as Real;
    let near: Vec<Real> = x
        .iter()
        .filter(|p| {
            let r = *p - centroid;
            (r - d * r.dot(&d)).norm() < 0.01
        })
        .map(|p| p.dot(&d))
        .collect();
    let thickness = near.iter().cloned().fold(Real::MIN, Real::max)
        - near.iter().cloned().fold(Real::MAX, Real::min);
    let touch = touch_distance(x, centroid, d, PROBE_RADIUS, pr);
    let contact = centroid - d * touch;
    let tool = world.add_tool(
        ToolShape::Sphere {
            radius: PROBE_RADIUS,
        },
        Pose::at(contact - d * 0.002),
        &ToolOptions::default(),
    )?;
    Ok((tool, contact, thickness))
}

/// Probe depth (m) beyond first contact at time `t` (s) of a press that goes in to `depth`
/// over `t_in`, holds for `t_hold` and comes out over `t_out` (starting 2 mm out).
fn depth_at(t: Real, depth: Real, t_in: Real, t_hold: Real, t_out: Real) -> Real {
    let back = -0.002;
    if t <= 0.0 {
        back
    } else if t < t_in {
        back + (depth - back) * t / t_in
    } else if t < t_in + t_hold {
        depth
    } else if t < t_in + t_hold + t_out {
        depth + (back - depth) * (t - t_in - t_hold) / t_out
    } else {
        back
    }
}

/// `volume`: paper Fig. 6, volume ratio over time with/without volume constraints, under
/// gravity alone and with a probe pressing 20% of the thickness. `--out CSV`.
pub fn volume_command(args: &Args) -> Res<()> {
    let out = PathBuf::from(args.string("out", "docs/data/volume_time.csv"));
    let mesh: String = args.string("mesh", "liver_4k");
    let fraction: Real = args.get("fraction", 0.2)?;
    let (t_settle, t_in, t_hold, t_out, t_end) = (1.5, 1.0, 1.0, 1.0, 5.0);
    let mut f = create(&out)?;
    writeln!(
        f,
        "run,volume_constraints,probe,time,depth,volume_ratio,max_displacement,force,substeps"
    )?;
    // `vol`: default (volumetric split: the constraints carry λ, compliance 1/λ); `novol`: no
    // volume constraints (full corotated stress on the particles); `hard`: the paper's literal
    // arrangement, full stress plus hard (compliance 0) volume constraints.
    for variant in ["vol", "novol", "hard"] {
        for probe in [false, true] {
            let vol = variant != "novol";
            let s = Settings {
                volumetric_split: variant == "vol",
                volume_compliance: 0.0,
                ..settings(vol)
            };
            let (mut world, id) = design_scene(&mesh, s)?;
            let dt = world.settings().dt;
            let steps = (t_end / dt).round() as usize;
            let mut tool = None;
            let name = format!("{}_{variant}", if probe { "probe" } else { "gravity" });
            let mut worst_press: Real = 0.0;
            for k in 1..=steps {
                let t = k as Real * dt;
                let mut depth = Real::NAN;
                if probe && tool.is_none() && t > t_settle {
                    let (tl, contact, thick) = add_probe(&mut world, id)?;
                    tool = Some((tl, contact, thick));
                    eprintln!("{name}: thickness along the press line {:.4} m", thick);
                }
                if let Some((tl, contact, thick)) = tool {
                    depth = depth_at(t - t_settle, fraction * thick, t_in, t_hold, t_out);
                    world.set_tool_pose(tl, Pose::at(contact + press_direction() * depth))?;
                }
                let rep = world.step()?;
                let b = world.body(id)?;
                let force = tool
                    .map(|(tl, _, _)| world.tool(tl).map(|x| x.wrench().force.norm()))
                    .transpose()?
                    .unwrap_or(0.0);
                if t > t_settle && t <= t_settle + t_in + t_hold {
                    worst_press = worst_press.max((b.volume_ratio() - 1.0).abs());
                }
                if k % 5 == 0 {
                    writeln!(
                        f,
                        "{name},{vol},{probe},{t:.4},{depth:.6},{:.8},{:.6e},{force:.6e},{}",
                        b.volume_ratio(),
                        b.max_displacement(),
                        rep.substeps
                    )?;
                }
            }
            eprintln!(
                "{name}: largest |V/V0 - 1| while pressing/holding {:.4}%",
                worst_press * 100.0
            );
        }
    }
    Ok(())
}

/// `runtime`: paper Fig. 7, ms per step with and without volume constraints on liver_1k6, 4k,
/// 10k (DESIGN §7 scene, a probe pressing 20% of the thickness). `--out CSV`.
pub fn runtime_command(args: &Args) -> Res<()> {
    let out = PathBuf::from(args.string("out", "docs/data/runtime.csv"));
    let meshes = args.string("meshes", "liver_1k6,liver_4k,liver_10k");
    let timed: usize = args.get("steps", 1000)?;
    let mut f = create(&out)?;
    writeln!(
        f,
        "mesh,nodes,tets,volume_constraints,substeps,steps,mean_ms,p50_ms,p99_ms,max_ms,volume_ratio"
    )?;
    for mesh in meshes.split(',') {
        for vol in [true, false] {
            let (mut world, id) = design_scene(mesh, settings(vol))?;
            settle(&mut world, 0.3)?;
            let (tool, contact, thick) = add_probe(&mut world, id)?;
            let mut ms = Vec::with_capacity(timed);
            let mut substeps = 0;
            for k in 1..=timed {
                let depth = 0.2 * thick * (2.0 * k as Real / timed as Real).min(1.0);
                let start = Instant::now();
                world.set_tool_pose(tool, Pose::at(contact + press_direction() * depth))?;
                substeps = substeps.max(world.step()?.substeps);
                ms.push(start.elapsed().as_secs_f64() * 1e3);
            }
            let b = world.body(id)?;
            let mean = ms.iter().sum::<Real>() / ms.len() as Real;
            let row = format!(
                "{mesh},{},{},{vol},{substeps},{timed},{mean:.4},{:.4},{:.4},{:.4},{:.6}",
                b.particle_count(),
                b.tets().len(),
                percentile(&ms, 0.5),
                percentile(&ms, 0.99),
                percentile(&ms, 1.0),
                b.volume_ratio()
            );
            println!("{row}");
            writeln!(f, "{row}")?;
        }
    }
    Ok(())
}

/// One large-deformation scenario's record.
struct Recorder {
    name: String,
    settled: Vec<Vec3>,
    trace: Vec<String>,
    peak_disp: Real,
    worst_inverted: usize,
    worst_min_ratio: Real,
    worst_volume: Real,
    snapshots: Vec<(String, Vec<Vec3>)>,
}

impl Recorder {
    fn new(name: &str, world: &World, id: BodyId) -> Res<Recorder> {
        Ok(Recorder {
            name: name.to_string(),
            settled: world.body(id)?.positions().to_vec(),
            trace: Vec::new(),
            peak_disp: 0.0,
            worst_inverted: 0,
            worst_min_ratio: Real::INFINITY,
            worst_volume: 0.0,
            snapshots: Vec::new(),
        })
    }
    fn disp(&self, world: &World, id: BodyId) -> Res<Real> {
        Ok(world
            .body(id)?
            .positions()
            .iter()
            .zip(&self.settled)
            .map(|(x, s)| (x - s).norm())
            .fold(0.0, Real::max))
    }
    fn record(&mut self, t: Real, world: &World, id: BodyId, force: Real) -> Res<()> {
        let d = self.disp(world, id)?;
        let (inv, minr) = inversion_stats(world, id)?;
        let vr = world.body(id)?.volume_ratio();
        self.peak_disp = self.peak_disp.max(d);
        self.worst_inverted = self.worst_inverted.max(inv);
        self.worst_min_ratio = self.worst_min_ratio.min(minr);
        self.worst_volume = self.worst_volume.max((vr - 1.0).abs());
        self.trace.push(format!(
            "{},{t:.4},{d:.6e},{vr:.8},{inv},{minr:.5},{force:.6e}",
            self.name
        ));
        Ok(())
    }
    fn snapshot(&mut self, tag: &str, world: &World, id: BodyId, dir: &Path) -> Res<()> {
        let x = world.body(id)?.positions().to_vec();
        write_vtu(
            &dir.join("vtu").join(format!("{}_{tag}.vtu", self.name)),
            world,
            id,
        )?;
        self.snapshots.push((tag.to_string(), x));
        Ok(())
    }
}

/// Move a probe/sweeper `tool` along `path(t)` for `t_total` seconds, recording every 10 steps.
#[allow(clippy::too_many_arguments)]
fn drive(
    world: &mut World,
    id: BodyId,
    tool: ToolId,
    rec: &mut Recorder,
    t0: Real,
    t_total: Real,
    path: &dyn Fn(Real) -> Vec3,
    peak_at: Real,
    dir: &Path,
) -> Res<()> {
    let dt = world.settings().dt;
    let steps = (t_total / dt).round() as usize;
    let peak_step = (peak_at / dt).round() as usize;
    for k in 1..=steps {
        let t = k as Real * dt;
        world.set_tool_pose(tool, Pose::at(path(t)))?;
        world.step()?;
        if k % 10 == 0 {
            let force = world.tool(tool)?.wrench().force.norm();
            rec.record(t0 + t, world, id, force)?;
        }
        if k == peak_step {
            rec.snapshot("peak", world, id, dir)?;
        }
    }
    Ok(())
}

/// `large`: paper Fig. 9, the liver under large deformation: a probe pressing 45% of the
/// thickness, a capsule sweeping the lower lobe sideways, and a grasped patch pulled 6 cm and
/// released. `--out DIR` gets the summary, the traces and surface snapshots (CSV), `DIR/vtu` the
/// VTU files for ParaView.
pub fn large_command(args: &Args) -> Res<()> {
    let dir = PathBuf::from(args.string("out", "build/evidence/large"));
    let summary_path = PathBuf::from(args.string("summary", "docs/data/large_deformation.csv"));
    std::fs::create_dir_all(&dir)?;
    let fraction: Real = args.get("fraction", 0.45)?;
    let mut records = Vec::new();
    let mut tris = Vec::new();
    let mut final_nonfinite = Vec::new();
    let mut diverged = Vec::new();
    for scenario in ["press", "sweep", "pull"] {
        let (mut world, id) = design_scene("liver_4k", settings(true))?;
        tris = world.body(id)?.boundary_triangles().to_vec();
        settle(&mut world, 2.0)?;
        let mut rec = Recorder::new(scenario, &world, id)?;
        rec.snapshot("settled", &world, id, &dir)?;
        let (t_load, t_hold, t_unload, t_recover) = (1.5, 0.5, 1.5, 2.0);
        let t_cycle = t_load + t_hold + t_unload;
        let (world, id) = match scenario {
            "press" => {
                let (tool, contact, thick) = add_probe(&mut world, id)?;
                let depth = fraction * thick;
                eprintln!("press: thickness {thick:.4} m, depth {depth:.4} m");
                let path = move |t: Real| {
                    contact + press_direction() * depth_at(t, depth, t_load, t_hold, t_unload)
                };
                drive(
                    &mut world,
                    id,
                    tool,
                    &mut rec,
                    0.0,
                    t_cycle + t_recover,
                    &path,
                    t_load + t_hold,
                    &dir,
                )?;
                (world, id)
            }
            "sweep" => {
                // A vertical capsule (r 1 cm) in the lower third, entering from the left (−x)
                // and sweeping 40% of the organ's width to the right, then back out.
                let (lo, hi) = bounds(world.body(id)?.positions());
                let y = lo.y + 0.3 * (hi.y - lo.y);
                let width = hi.x - lo.x;
                let b = world.body(id)?;
                let origin = Vec3::new(0.0, y, 0.0);
                let dx = Vec3::x();
                let touch = touch_distance(b.positions(), origin, dx, 0.012, b.particle_radius());
                let start = origin - dx * (touch + 0.002);
                let travel = 0.4 * width;
                eprintln!("sweep: width {width:.4} m, travel {travel:.4} m");
                let tool = world.add_tool(
                    ToolShape::Capsule {
                        half_height: 0.03,
                        radius: 0.01,
                    },
                    Pose::at(start),
                    &ToolOptions {
                        friction_static: 0.3,
                        friction_kinetic: 0.2,
                        sample_spacing: None,
                    },
                )?;
                let path = move |t: Real| {
                    start + dx * (0.002 + depth_at(t, travel, t_load, t_hold, t_unload))
                };
                drive(
                    &mut world,
                    id,
                    tool,
                    &mut rec,
                    0.0,
                    t_cycle + t_recover,
                    &path,
                    t_load + t_hold,
                    &dir,
                )?;
                (world, id)
            }
            _ => {
                // Grasp the particles within 2 cm of the lowest point, pull them 5 cm down and
                // 3 cm forward (prescribed positions of fixed particles), hold, then release:
                // a fresh world without the grasp takes over the state.
                let b = world.body(id)?;
                let x0 = b.positions().to_vec();
                let low = *x0
                    .iter()
                    .min_by(|a, b| a.y.partial_cmp(&b.y).unwrap())
                    .unwrap();
                let grasp: Vec<u32> = (0..x0.len() as u32)
                    .filter(|&i| (x0[i as usize] - low).norm() < 0.02 && !b.is_fixed(i as usize))
                    .collect();
                world.fix_particles(id, &grasp)?;
                let pull = Vec3::new(0.0, -0.05, 0.03);
                let dt = world.settings().dt;
                let n_load = (t_load / dt).round() as usize;
                let n_hold = (t_hold / dt).round() as usize;
                let zeros = vec![Vec3::zeros(); x0.len()];
                for k in 1..=n_load + n_hold {
                    let s = (k as Real / n_load as Real).min(1.0);
                    let mut x = world.body(id)?.positions().to_vec();
                    let v = world.body(id)?.velocities().to_vec();
                    for &i in &grasp {
                        x[i as usize] = x0[i as usize] + pull * s;
                    }
                    let _ = &zeros;
                    world.set_body_state(id, &x, &v)?;
                    world.step()?;
                    if k % 10 == 0 {
                        rec.record(k as Real * dt, &world, id, 0.0)?;
                    }
                }
                rec.snapshot("peak", &world, id, &dir)?;
                eprintln!("pull: {} grasped particles", grasp.len());
                // Release.
                let (mut free, fid) = design_scene("liver_4k", settings(true))?;
                let b = world.body(id)?;
                free.set_body_state(fid, b.positions(), b.velocities())?;
                let n_rec = ((t_unload + t_recover) / dt).round() as usize;
                for k in 1..=n_rec {
                    free.step()?;
                    if k % 10 == 0 {
                        rec.record(t_load + t_hold + k as Real * dt, &free, fid, 0.0)?;
                    }
                }
                (free, fid)
            }
        };
        rec.snapshot("released", &world, id, &dir)?;
        let end_disp = rec.disp(&world, id)?;
        let (inv_end, minr_end) = inversion_stats(&world, id)?;
        let finite = world
            .body(id)?
            .positions()
            .iter()
            .all(|p| p.iter().all(|c| c.is_finite()));
        final_nonfinite.push(!finite);
        diverged.push(world.diverged_steps());
        records.push((
            rec,
            end_disp,
            inv_end,
            minr_end,
            world.body(id)?.volume_ratio(),
        ));
    }
    write_triangles(&dir.join("boundary_triangles.csv"), &tris)?;
    let mut trace = create(&dir.join("large_trace.csv"))?;
    writeln!(
        trace,
        "scenario,time,max_disp_from_settled,volume_ratio,inverted_tets,min_tet_volume_ratio,force"
    )?;
    let mut summary = create(&summary_path)?;
    writeln!(
        summary,
        "scenario,peak_disp_m,end_disp_m,recovered_pct,worst_inverted_tets,worst_min_tet_ratio,\
         worst_volume_error_pct,inverted_tets_after_release,min_tet_ratio_after_release,\
         volume_ratio_after_release,diverged_steps,non_finite"
    )?;
    for (k, (rec, end_disp, inv_end, minr_end, vr)) in records.iter().enumerate() {
        for line in &rec.trace {
            writeln!(trace, "{line}")?;
        }
        for (tag, x) in &rec.snapshots {
            write_positions(&dir.join(format!("{}_{tag}.csv", rec.name)), x)?;
        }
        let row = format!(
            "{},{:.5},{:.6},{:.2},{},{:.4},{:.3},{},{:.4},{:.6},{},{}",
            rec.name,
            rec.peak_disp,
            end_disp,
            100.0 * (1.0 - end_disp / rec.peak_disp),
            rec.worst_inverted,
            rec.worst_min_ratio,
            100.0 * rec.worst_volume,
            inv_end,
            minr_end,
            vr,
            diverged[k],
            final_nonfinite[k]
        );
        println!("{row}");
        writeln!(summary, "{row}")?;
    }
    Ok(())
}
