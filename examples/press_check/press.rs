//! One deep press of the contact goal on a hung organ, measured every step against the deformed
//! boundary surface, independently of the library's own contact report (docs/VALIDATION.md §5):
//! the organ hung by its top 15% and settled, a sphere pressed horizontally through the middle of
//! its rest bounding box at 5 cm/s from 2 mm off the surface, some depth past first contact,
//! held, and withdrawn. Measured:
//! - the probe's centre inside the organ (generalised winding number, `Body::contains`);
//! - the depth of the surface inside the probe: the radius less the distance from the centre to
//!   the nearest boundary triangle;
//! - the contact steps whose force on the probe has a component along the press (pulling);
//! - the tissue: the most tetrahedra inverted at once, the fastest particle (m/s), and the steps
//!   that diverged (rolled back by the library; the press goes on).
//!
//! A press meets the goal when the centre is never inside, the surface never more than a fifth
//! of the radius inside the probe, no contact step pulls and no step diverges. A press whose
//! probe touched the organ on less than 40% of its pressing steps (the press line grazes or
//! misses the organ) is not judged.
//!
//! Shared by `examples/press_check` (any organ, from the command line) and the suite's
//! `tests/contact_press_check.rs`.

use parry3d_f64::math::{Point, Vector};
use parry3d_f64::query::{PointQuery, Ray, RayCast};
use parry3d_f64::shape::Triangle;
use std::path::{Path, PathBuf};
use tissuesim::{mesh, tet_volume, Body, BodyOptions, Pose, Real, Settings, ToolOptions};
use tissuesim::{Error, World, WorldState};
use tissuesim::{ToolShape, Vec3};

pub type Res<T> = Result<T, Box<dyn std::error::Error>>;

/// Probe speed along the press (m/s).
const SPEED: Real = 0.05;
/// Gap (m) between the probe and the surface (plus the contact skin) at the start.
const GAP: Real = 0.002;
/// Fraction of the organ's height, from its top, held fixed.
const FIXED_TOP: Real = 0.15;
/// Most of the probe's radius the surface may get inside it (the contact goal).
const MOST_INSIDE: Real = 0.2;
/// Least share of the pressing steps in contact for a press to be judged.
const LEAST_CONTACT: Real = 0.4;

/// What one press measured.
pub struct Press {
    /// Largest depth (m) of the surface inside the probe; negative: it stayed outside.
    pub deepest: Real,
    /// Steps with the probe's centre inside the deformed surface.
    pub centre_inside: usize,
    /// Contact steps of the press and hold whose force pulled the probe along the press.
    pub pulling: usize,
    /// Largest force (N) along the press on a pulling step.
    pub strongest_pull: Real,
    /// Steps of the press and hold in contact, of `pressing_steps`.
    pub contact_steps: usize,
    pub pressing_steps: usize,
    /// Most tetrahedra inverted at once.
    pub inverted: usize,
    /// Fastest particle (m/s).
    pub fastest: Real,
    /// Steps that diverged and were rolled back (the tool moves on).
    pub rolled_back: usize,
}

impl Press {
    /// Whether the probe touched the organ on enough of its pressing steps to be judged.
    pub fn touched(&self) -> bool {
        self.contact_steps as Real >= LEAST_CONTACT * self.pressing_steps as Real
    }

    /// Whether the press of a sphere of `radius` (m) meets the goal.
    pub fn meets(&self, radius: Real) -> bool {
        self.centre_inside == 0
            && self.deepest <= MOST_INSIDE * radius
            && self.pulling == 0
            && self.rolled_back == 0
    }

    /// The press as a row of the report: `name`, `radius` (m), `side`, then the figures and the
    /// verdict.
    pub fn row(&self, name: &str, radius: Real, side: &str) -> String {
        let verdict = match (self.touched(), self.meets(radius)) {
            (false, _) => "not judged (grazes the organ)",
            (true, true) => "meets",
            (true, false) => "misses",
        };
        format!(
            "{name} | {} | {side} | {} | {:.2} | {} ({:.3}) | {} of {} | {} | {:.2} | {} | {verdict}",
            radius * 1e3,
            self.centre_inside,
            self.deepest / radius,
            self.pulling,
            self.strongest_pull,
            self.contact_steps,
            self.pressing_steps,
            self.inverted,
            self.fastest,
            self.rolled_back
        )
    }
}

/// The header of [`Press::row`].
pub const HEADER: &str = "mesh | radius mm | side | centre inside | deepest / radius | pulling steps (strongest, N) | contact | most inverted | fastest m/s | rolled back | goal";

/// The settled hanging organ that every press starts from.
pub struct Hanging {
    /// The body's model, shared by every press's world.
    pub model: std::sync::Arc<tissuesim::BodyModel>,
    /// The world's state once settled.
    pub state: WorldState,
    /// The middle (m) of the rest bounding box, which the presses go through.
    pub middle: Vec3,
    /// The boundary triangles once settled, where the presses start from.
    pub triangles: Vec<Triangle>,
    /// The body's contact skin (m).
    pub skin: Real,
}

/// The mesh at `name`: a file, or a name in `data/meshes`.
fn mesh_path(name: &str) -> PathBuf {
    let given = PathBuf::from(name);
    let node = given.with_extension("node");
    if given.is_file() || node.is_file() {
        return given;
    }
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("data/meshes")
        .join(name)
}

/// Load `name` at `scale` (m per mesh unit), centre it, hang it by its top and settle it.
pub fn hang(name: &str, scale: Real, settings: &Settings) -> Res<Hanging> {
    let (mut organ, _) = mesh::load(&mesh_path(name), scale)?;
    let (lo, hi) = organ.bounding_box();
    let centre = (lo + hi) * 0.5;
    organ.nodes.iter_mut().for_each(|p| *p -= centre);
    let mut world = World::new(settings.clone())?;
    let body = world.add_body(&organ, &BodyOptions::default())?;
    let (lo, hi) = (lo - centre, hi - centre);
    let top = hi.y - FIXED_TOP * (hi.y - lo.y);
    let margin = 1.0;
    let fixed = world.fix_box(
        body,
        Vec3::new(lo.x - margin, top, lo.z - margin),
        hi.add_scalar(margin),
    )?;
    if fixed == 0 {
        return Err(format!("{name}: no particle in the top {FIXED_TOP} of the organ").into());
    }
    world.settle()?;
    let b = world.body(body)?;
    Ok(Hanging {
        model: b.model().clone(),
        state: world.state(),
        triangles: surface(b),
        skin: b.contact_skin(),
        middle: {
            let rest = b.rest_positions().iter();
            let (lo, hi) = rest.fold(
                (Vec3::repeat(Real::MAX), -Vec3::repeat(Real::MAX)),
                |(lo, hi), p| (lo.inf(p), hi.sup(p)),
            );
            (lo + hi) * 0.5
        },
    })
}

/// The boundary triangles of `body` at its current positions.
fn surface(body: &Body) -> Vec<Triangle> {
    let x = body.positions();
    let point = |k: u32| Point::from(x[k as usize]);
    let triangles = body.boundary_triangles().iter();
    triangles
        .map(|t| Triangle::new(point(t[0]), point(t[1]), point(t[2])))
        .collect()
}

/// Distance (m) from `p` to the nearest of `triangles`.
fn distance(triangles: &[Triangle], p: &Vec3) -> Real {
    let p = Point::from(*p);
    let each = triangles
        .iter()
        .map(|t| t.distance_to_local_point(&p, true));
    each.fold(Real::INFINITY, Real::min)
}

/// Where a probe reaching `reach` (m) starts on the line through `through` along `direction`:
/// `GAP` plus `skin` before the first boundary triangle the line meets, then moved back until
/// no part of the surface is nearer than that (a curved surface can bulge towards the probe off
/// the line). `None` when the line misses the organ.
fn start(
    triangles: &[Triangle],
    (through, direction): (Vec3, Vec3),
    reach: Real,
    skin: Real,
) -> Option<Vec3> {
    let far = 10.0;
    let ray = Ray::new(
        Point::from(through - direction * far),
        Vector::from(direction),
    );
    let hit = triangles
        .iter()
        .filter_map(|t| t.cast_local_ray(&ray, 2.0 * far, false))
        .fold(Real::INFINITY, Real::min);
    if !hit.is_finite() {
        return None;
    }
    let clearance = reach + skin + GAP;
    let mut centre = through + direction * (hit - far - clearance);
    for _ in 0..100 {
        if distance(triangles, &centre) >= clearance {
            break;
        }
        centre -= direction * 0.001;
    }
    Some(centre)
}

/// The press of a sphere of `radius` (m) from `side` (`+x`, `-x`, `+z` or `-z`: the direction
/// it moves in) through the middle of `organ`, `depth` (m) past first contact and held `hold`
/// (s); `None` when the press line misses the organ.
pub fn press_from(
    organ: &Hanging,
    settings: &Settings,
    radius: Real,
    side: &str,
    (depth, hold): (Real, Real),
) -> Res<Option<Press>> {
    let m = organ.middle;
    let (direction, through) = match side {
        "+x" | "-x" => (Vec3::x(), Vec3::new(0.0, m.y, m.z)),
        "+z" | "-z" => (Vec3::z(), Vec3::new(m.x, m.y, 0.0)),
        s => return Err(format!("unknown side {s} (+x, -x, +z, -z)").into()),
    };
    let direction = if side.starts_with('-') {
        -direction
    } else {
        direction
    };
    let line = (through, direction);
    let Some(from) = start(&organ.triangles, line, radius, organ.skin) else {
        return Ok(None);
    };
    press(organ, settings, radius, (from, direction), (depth, hold)).map(Some)
}

/// One press of a sphere of `radius` (m) from `start` along `direction`.
fn press(
    organ: &Hanging,
    settings: &Settings,
    radius: Real,
    (start, direction): (Vec3, Vec3),
    (depth, hold): (Real, Real),
) -> Res<Press> {
    let mut world = World::new(settings.clone())?;
    let body = world.add_body_model(organ.model.clone());
    world.set_state(&organ.state)?;
    let probe = ToolShape::Sphere { radius };
    let tool = world.add_tool(probe, Pose::at(start), &ToolOptions::default())?;
    let dt = world.settings().dt;
    let press_steps = ((GAP + depth) / SPEED / dt).round() as usize;
    let hold_steps = (hold / dt).round() as usize;
    let total = 2 * press_steps + hold_steps;
    let tets = world.body(body)?.tets().to_vec();
    let mut p = Press {
        deepest: Real::NEG_INFINITY,
        centre_inside: 0,
        pulling: 0,
        strongest_pull: 0.0,
        contact_steps: 0,
        pressing_steps: press_steps + hold_steps,
        inverted: 0,
        fastest: 0.0,
        rolled_back: 0,
    };
    for k in 1..=total {
        let along = k.min(press_steps).min(total - k) as Real;
        let centre = start + direction * (SPEED * dt * along);
        world.set_tool_pose(tool, Pose::at(centre))?;
        match world.step() {
            Ok(_) => {}
            Err(Error::Diverged(_)) => p.rolled_back += 1,
            Err(e) => return Err(e.into()),
        }
        let b = world.body(body)?;
        p.deepest = p.deepest.max(radius - distance(&surface(b), &centre));
        p.centre_inside += b.contains(&centre) as usize;
        let x = b.positions();
        let corners = |t: &[u32; 4]| t.map(|k| x[k as usize]);
        let inverted =
            (tets.iter().map(corners)).filter(|[p, q, r, s]| tet_volume(p, q, r, s) < 0.0);
        p.inverted = p.inverted.max(inverted.count());
        let speeds = b.velocities().iter().map(|v| v.norm());
        p.fastest = speeds.fold(p.fastest, Real::max);
        let wrench = world.tool(tool)?.wrench();
        if wrench.contact_count > 0 && k <= press_steps + hold_steps {
            p.contact_steps += 1;
            let along = wrench.force.dot(&direction);
            p.pulling += (along > 0.0) as usize;
            p.strongest_pull = p.strongest_pull.max(along);
        }
    }
    Ok(p)
}
