//! The TissueSim model: its variable table (the single source of `modelDescription.xml` and of
//! the compiled getters/setters) and the mapping of those variables to a [`tissuesim::World`]
//! holding one organ and one kinematic tool.
//!
//! * The world is built at `fmi2ExitInitializationMode` (or when an output is read in
//!   initialisation mode) from the parameters; the mesh is read from the FMU's `resources/`
//!   directory (or an absolute path; `""` selects the embedded default organ).
//! * `fmi2DoStep(t, h)` runs `n = ceil(h / internal_step)` world steps of `h / n` each and moves
//!   the tool from the pose it had at `t` to the input pose, linearly in position and by slerp
//!   in orientation, one interpolated pose per world step (so a long communication step never
//!   teleports the tool into the organ).
//! * Outputs: force and torque on the tool averaged over the communication step; contact
//!   count, penetration, volume and displacement at its end.

use crate::fmi2::bytes::{PutBytes, Reader};
use crate::fmi2::{
    Causality::{Input, Output, Parameter},
    DefaultExperiment, EnumItem, EnumType, Kind, Logger, Model, ModelError, Store, UnitDefinition,
    Value, Variability,
    Variability::{Continuous, Discrete, Fixed, Tunable},
    Variable,
};

use std::path::{Path, PathBuf};
use tissuesim::Quat;
use tissuesim::{
    mesh, BodyId, BodyOptions, ElasticScheme, Error, GraspOptions, Material, NeedleOptions, Pose,
    Settings, ToolId, ToolOptions, ToolShape, Vec3, VolumeScheme, World,
};

/// Default tool position (m): ~1.7 cm in front (+z) of the default organ's right lobe at
/// mid-height. The organ hangs from its fixed top and sags several centimetres under gravity,
/// parallel to that face, so it does not touch the probe until the probe moves along -z.
pub const DEFAULT_TOOL_POSITION: [f64; 3] = [0.035, 0.0, 0.095];
/// Default fixed box (m): every node in the top ~15 % of the default organ's height.
pub const DEFAULT_FIXED_MIN: [f64; 3] = [-0.2, 0.043, -0.2];
/// Upper corner of the default fixed box (m).
pub const DEFAULT_FIXED_MAX: [f64; 3] = [0.2, 0.2, 0.2];
/// Default mesh file, inside the FMU's `resources/`.
pub const DEFAULT_MESH: &str = "organ.vtk";

/// The tool shapes (`tool_shape`).
pub static TOOL_SHAPE_TYPE: EnumType = EnumType {
    name: "ToolShape",
    description: "Shape of the tool, centred on its origin, axis along its local y",
    items: &[
        EnumItem {
            name: "sphere",
            value: 0,
            description: "sphere of radius tool_radius",
        },
        EnumItem {
            name: "capsule",
            value: 1,
            description:
                "capsule: segment of half length tool_half_length along local y, radius tool_radius",
        },
        EnumItem {
            name: "cylinder",
            value: 2,
            description:
                "cylinder of half length tool_half_length along local y, radius tool_radius",
        },
        EnumItem {
            name: "box",
            value: 3,
            description: "box of half extents (tool_radius, tool_half_length, tool_radius)",
        },
    ],
};

/// The elastic schemes (`elastic_scheme`), numbered as the C API's `ts_elastic_scheme`.
pub static ELASTIC_SCHEME_TYPE: EnumType = EnumType {
    name: "ElasticScheme",
    description: "Discretisation of the organ's elasticity",
    items: &[
        EnumItem {
            name: "tetrahedra",
            value: 0,
            description: "corotated linear tetrahedra (the default)",
        },
        EnumItem {
            name: "point_based",
            value: 1,
            description: "the paper's point-based particles (MLS deformation gradients)",
        },
    ],
};

/// The volume schemes (`volume_scheme`), numbered as the C API's `ts_volume_scheme`.
pub static VOLUME_SCHEME_TYPE: EnumType = EnumType {
    name: "VolumeScheme",
    description: "Where the volume constraints sit",
    items: &[
        EnumItem {
            name: "dual_cells",
            value: 0,
            description: "one constraint per particle on its dual cell (the default)",
        },
        EnumItem {
            name: "tetrahedra",
            value: 1,
            description: "one constraint per tetrahedron (the paper's)",
        },
    ],
};

const fn input(name: &'static str, unit: &'static str, start: f64, d: &'static str) -> Variable {
    Variable::real(name, Input, Continuous, unit, Some(start), None, None, d)
}

const fn output(name: &'static str, unit: &'static str, d: &'static str) -> Variable {
    Variable::real(name, Output, Continuous, unit, None, None, None, d)
}

const fn param(
    name: &'static str,
    variability: Variability,
    unit: &'static str,
    start: f64,
    min: Option<f64>,
    d: &'static str,
) -> Variable {
    Variable::real(
        name,
        Parameter,
        variability,
        unit,
        Some(start),
        min,
        None,
        d,
    )
}

crate::fmi2_variables! {
    /// Value references, one constant per variable (value reference = row of [`VARIABLES`]).
    pub mod vr;
    /// The variable table: the single declaration of every variable, from which
    /// `modelDescription.xml`, the [`vr`] constants and the variables table of `docs/FMU.md`
    /// are generated.
    pub static VARIABLES = [
        TOOL_PX = input("tool_px", "m", DEFAULT_TOOL_POSITION[0], "Tool origin position x (world frame)"),
        TOOL_PY = input("tool_py", "m", DEFAULT_TOOL_POSITION[1], "Tool origin position y (world frame, y up)"),
        TOOL_PZ = input("tool_pz", "m", DEFAULT_TOOL_POSITION[2], "Tool origin position z (world frame)"),
        TOOL_QW = input("tool_qw", "", 1.0, "Tool orientation quaternion w (local to world; normalised on use, must not be zero)"),
        TOOL_QX = input("tool_qx", "", 0.0, "Tool orientation quaternion x"),
        TOOL_QY = input("tool_qy", "", 0.0, "Tool orientation quaternion y"),
        TOOL_QZ = input("tool_qz", "", 0.0, "Tool orientation quaternion z"),
        FORCE_X = output("force_x", "N", "Force exerted by the tissue on the tool, x (world frame, averaged over the communication step)"),
        FORCE_Y = output("force_y", "N", "Force exerted by the tissue on the tool, y"),
        FORCE_Z = output("force_z", "N", "Force exerted by the tissue on the tool, z"),
        TORQUE_X = output("torque_x", "N.m", "Torque exerted by the tissue on the tool about its origin, x (world frame, averaged over the communication step)"),
        TORQUE_Y = output("torque_y", "N.m", "Torque on the tool about its origin, y"),
        TORQUE_Z = output("torque_z", "N.m", "Torque on the tool about its origin, z"),
        VOLUME = output("volume", "m3", "Current organ volume (sum of signed tetrahedron volumes) at the end of the step"),
        VOLUME_RATIO = output("volume_ratio", "", "Organ volume / rest volume at the end of the step"),
        CONTACT_COUNT = Variable::integer("contact_count", Output, Discrete, None, Some(0), None, "Number of organ surface triangles in contact with the tool at the end of the step"),
        MAX_DISPLACEMENT = output("max_displacement", "m", "Largest distance of an organ particle from its rest position at the end of the step"),
        MAX_PENETRATION = output("max_penetration", "m", "Largest contact violation before projection (how far the surface was inside the tool's contact skin), last internal step"),
        YOUNGS_MODULUS = param("youngs_modulus", Fixed, "Pa", 5.0e3, Some(0.0), "Young's modulus E of the organ"),
        POISSON_RATIO = Variable::real("poisson_ratio", Parameter, Fixed, "", Some(0.45), Some(tissuesim::MIN_POISSON_RATIO), Some(tissuesim::MAX_POISSON_RATIO), "Poisson ratio nu of the organ, in [0, 0.499] (no auxetic tissue; the volumetric stiffness diverges at 0.5)"),
        DENSITY = param("density", Fixed, "kg/m3", 1060.0, Some(0.0), "Mass density of the organ"),
        DAMPING = param("damping", Tunable, "1/s", 2.0, Some(0.0), "Mass-proportional (ambient) damping rate alpha: velocities scale by 1/(1 + alpha h) per substep of length h"),
        FRICTION_STATIC = param("friction_static", Fixed, "", 0.2, Some(0.0), "Static friction coefficient between tool and tissue"),
        FRICTION_KINETIC = param("friction_kinetic", Fixed, "", 0.1, Some(0.0), "Kinetic friction coefficient between tool and tissue (<= friction_static)"),
        TOOL_SHAPE = Variable::enumeration("tool_shape", Parameter, Fixed, &TOOL_SHAPE_TYPE, 0, "Tool shape: 0 sphere, 1 capsule, 2 cylinder, 3 box"),
        TOOL_RADIUS = param("tool_radius", Fixed, "m", 0.01, Some(0.0), "Tool radius (sphere, capsule, cylinder) or half width (box)"),
        TOOL_HALF_LENGTH = param("tool_half_length", Fixed, "m", 0.03, Some(0.0), "Half length of a capsule, cylinder or box along the tool's local y axis"),
        INTERNAL_STEP = param("internal_step", Tunable, "s", 1.0e-3, Some(0.0), "Largest internal time step: fmi2DoStep(h) runs ceil(h/internal_step) world steps of equal length"),
        VOLUME_COMPLIANCE = param("volume_compliance", Tunable, "1/Pa", 0.0, Some(0.0), "Extra compliance of the volume constraints (one per particle's dual cell), added to what the material gives them; 0 = the material's own compressibility"),
        VOLUME_CONSTRAINTS = Variable::boolean("volume_constraints", Parameter, Tunable, true, "Enable the volume constraints (one per particle's dual cell)"),
        MESH = Variable::string("mesh", Parameter, Fixed, DEFAULT_MESH, "Organ mesh: a file in the FMU's resources/ or an absolute path (.msh, .node/.ele, .vtk); empty = the embedded default organ"),
        MESH_SCALE = param("mesh_scale", Fixed, "", 1.0, Some(0.0), "Factor from mesh units to metres"),
        FIXED_MIN_X = param("fixed_min_x", Fixed, "m", DEFAULT_FIXED_MIN[0], None, "Lower corner x of the box whose nodes are fixed (empty box: none)"),
        FIXED_MIN_Y = param("fixed_min_y", Fixed, "m", DEFAULT_FIXED_MIN[1], None, "Lower corner y of the fixed box"),
        FIXED_MIN_Z = param("fixed_min_z", Fixed, "m", DEFAULT_FIXED_MIN[2], None, "Lower corner z of the fixed box"),
        FIXED_MAX_X = param("fixed_max_x", Fixed, "m", DEFAULT_FIXED_MAX[0], None, "Upper corner x of the fixed box"),
        FIXED_MAX_Y = param("fixed_max_y", Fixed, "m", DEFAULT_FIXED_MAX[1], None, "Upper corner y of the fixed box"),
        FIXED_MAX_Z = param("fixed_max_z", Fixed, "m", DEFAULT_FIXED_MAX[2], None, "Upper corner z of the fixed box"),
        GRAVITY_X = param("gravity_x", Tunable, "m/s2", 0.0, None, "Gravity acceleration x"),
        GRAVITY_Y = param("gravity_y", Tunable, "m/s2", -9.81, None, "Gravity acceleration y"),
        GRAVITY_Z = param("gravity_z", Tunable, "m/s2", 0.0, None, "Gravity acceleration z"),
        THREADS = Variable::integer("threads", Parameter, Fixed, Some(1), Some(1), Some(64), "Threads of a step (the calling thread plus threads - 1 workers, sharing the force, volume, prediction and update passes); results are bit-identical for any count"),
        SETTLE = Variable::boolean("settle", Parameter, Fixed, false, "Start at rest: at fmi2ExitInitializationMode the organ is brought to its static equilibrium under gravity (World::settle: Newton static solve, then damped relaxation; velocities zero), so the co-simulation does not start with the organ swinging into place; an organ with no fixed node cannot settle (fmi2Error)"),
        GRASP = Variable::boolean("grasp", Input, Discrete, false, "Grasp: while true the tool holds the tissue within reach of its surface (compliant attachments; the pull shows in force_*); at each communication step a tool that holds nothing grasps what is within reach, and false releases"),
        GRASPED_COUNT = Variable::integer("grasped_count", Output, Discrete, None, Some(0), None, "Number of organ particles the tool holds at the end of the step (0 when not grasping)"),
        NEEDLE_PUNCTURE_FORCE = param("needle_puncture_force", Fixed, "N", 0.0, Some(0.0), "Above 0 the tool (a capsule or cylinder; shaft along its local y, tip at +y) is a needle: it punctures the organ when the tissue pushes back on its tip with this force, then holds the tissue on its shaft with friction (World::make_needle); 0 = an ordinary tool"),
        NEEDLE_FRICTION = param("needle_friction", Fixed, "N/m", 10.0, Some(0.0), "Axial friction of an inserted needle per metre of inserted length"),
        NEEDLE_DEPTH = output("needle_depth", "m", "How far the needle's tip is past its entry point along the shaft at the end of the step (0 before puncture, after withdrawal, or when the tool is not a needle)"),
        ELASTIC_SCHEME = Variable::enumeration("elastic_scheme", Parameter, Fixed, &ELASTIC_SCHEME_TYPE, 0, "Elasticity: 0 corotated tetrahedra (the default), 1 the paper's point-based particles"),
        VOLUME_SCHEME = Variable::enumeration("volume_scheme", Parameter, Fixed, &VOLUME_SCHEME_TYPE, 0, "Volume constraints: 0 one per particle's dual cell (the default), 1 one per tetrahedron (the paper's)"),
        DAMPING_STIFFNESS = param("damping_stiffness", Tunable, "s", 3.0e-4, Some(0.0), "Stiffness-proportional damping time beta: dashpots on the tetrahedra's edges, filtered implicitly (no substeps added), for both elastic schemes; 0 for none"),
        MIN_SUBSTEPS = Variable::integer("min_substeps", Parameter, Tunable, Some(1), Some(1), Some(64), "Fewest solver substeps per internal step (more where the stability limit or a fast tool needs them)"),
        CRUSHED_SUBSTEPS = Variable::integer("crushed_substeps", Parameter, Tunable, Some(1), Some(1), Some(64), "Fewest solver substeps of an internal step that starts with the tissue at the tool compressed (a tetrahedron touching it below half its rest volume, now or two steps ahead); 1 adds none (where the tool is narrower than the crushed tetrahedra the step takes twice its substeps anyway), 2 keeps wide probes pressed deep out of the tissue at twice the cost of those steps"),
    ];
}
const fn unit(name: &'static str, kg: i32, m: i32, s: i32) -> UnitDefinition {
    UnitDefinition { name, kg, m, s }
}

/// The units of the variables, with their SI base-unit exponents.
pub static UNITS: &[UnitDefinition] = &[
    unit("m", 0, 1, 0),
    unit("m3", 0, 3, 0),
    unit("s", 0, 0, 1),
    unit("1/s", 0, 0, -1),
    unit("N", 1, 1, -2),
    unit("N.m", 1, 2, -2),
    unit("N/m", 1, 0, -2),
    unit("Pa", 1, -1, -2),
    unit("1/Pa", -1, 1, 2),
    unit("kg/m3", 1, -3, 0),
    unit("m/s2", 0, 1, -2),
];

/// The simulation built from the parameters.
struct Sim {
    world: World,
    body: BodyId,
    tool: ToolId,
    /// Values of the fixed parameters it was built from (a state saved with other values
    /// needs a rebuilt world).
    built_from: Vec<Value>,
    /// Tool pose at the end of the last step: the start of the next interpolation.
    pose: Pose,
}

/// The model behind the FMU (see the module documentation).
pub struct TissueSim {
    resources: Option<PathBuf>,
    sim: Option<Sim>,
    /// World state at the start of the current step, for rolling back a failed step.
    snapshot: Vec<u8>,
}

const STATE_NO_SIM: u8 = 0;
const STATE_SIM: u8 = 1;

impl Model for TissueSim {
    const MODEL_IDENTIFIER: &'static str = "TissueSim";
    const DESCRIPTION: &'static str = "Real-time soft-tissue solver (corotated elasticity, position-based contact and volume conservation): a kinematic tool pressing an organ; inputs tool pose, outputs contact force/torque and organ volume";
    const VARIABLES: &'static [Variable] = VARIABLES;
    const UNITS: &'static [UnitDefinition] = UNITS;
    const ENUMERATIONS: &'static [&'static EnumType] =
        &[&TOOL_SHAPE_TYPE, &ELASTIC_SCHEME_TYPE, &VOLUME_SCHEME_TYPE];
    const DEFAULT_EXPERIMENT: DefaultExperiment = DefaultExperiment {
        start_time: 0.0,
        stop_time: 1.0,
        step_size: 1.0e-3,
    };
    const STATE_MAGIC: [u8; 8] = *b"TSFMUST\0";

    fn new(resources: Option<PathBuf>) -> Self {
        TissueSim {
            resources,
            sim: None,
            snapshot: Vec::new(),
        }
    }

    fn initialize(&mut self, store: &mut Store, log: &Logger) -> Result<(), ModelError> {
        let mut sim = build(store, self.resources.as_deref(), log).map_err(ModelError::error)?;
        if store.boolean(vr::SETTLE) {
            settle(&mut sim, log)?;
        }
        write_outputs(store, &sim, Vec3::zeros(), Vec3::zeros())?;
        self.sim = Some(sim);
        Ok(())
    }

    fn do_step(
        &mut self,
        store: &mut Store,
        _t: f64,
        h: f64,
        log: &Logger,
    ) -> Result<(), ModelError> {
        let sim = self
            .sim
            .as_mut()
            .ok_or_else(|| ModelError::error("the world was not built"))?;
        let target = pose_from_inputs(store).map_err(ModelError::error)?;
        let n = substeps(h, store.real(vr::INTERNAL_STEP)).map_err(ModelError::error)?;
        let dt = h / n as f64;
        let settings = settings_from(store, sim.world.settings(), dt);
        self.snapshot.clear();
        sim.world.save_state(&mut self.snapshot);
        apply_grasp(sim, store.boolean(vr::GRASP)).map_err(|e| ModelError::error(e.to_string()))?;
        let start_pose = sim.pose;
        let result = run_steps(sim, &settings, start_pose, target, n, log);
        match result {
            Ok((force, torque)) => {
                sim.pose = target;
                write_outputs(store, sim, force, torque)
            }
            Err(e) => {
                if let Err(r) = sim.world.restore_state(&self.snapshot) {
                    return Err(ModelError::error(format!(
                        "{}; rolling back also failed: {r}",
                        e.message
                    )));
                }
                Err(e)
            }
        }
    }

    fn reset(&mut self) {
        self.sim = None;
    }

    fn save_state(&self, out: &mut Vec<u8>) {
        match &self.sim {
            None => out.put_u8(STATE_NO_SIM),
            Some(sim) => {
                out.put_u8(STATE_SIM);
                let p = sim.pose.position;
                let q = sim.pose.orientation.quaternion();
                for v in [p.x, p.y, p.z, q.w, q.i, q.j, q.k] {
                    out.put_f64(v);
                }
                let mut world = Vec::with_capacity(sim.world.state_size());
                sim.world.save_state(&mut world);
                out.put_blob(&world);
            }
        }
    }

    fn restore_state(
        &mut self,
        store: &Store,
        bytes: &[u8],
        log: &Logger,
    ) -> Result<(), ModelError> {
        let mut r = Reader::new(bytes);
        let bad = |e: String| ModelError::error(format!("bad model state: {e}"));
        match r.u8().map_err(bad)? {
            STATE_NO_SIM => {
                r.finish().map_err(bad)?;
                self.sim = None;
                Ok(())
            }
            STATE_SIM => {
                let mut c = [0.0; 7];
                for v in &mut c {
                    *v = r.f64().map_err(bad)?;
                }
                let world = r.blob().map_err(bad)?;
                r.finish().map_err(bad)?;
                let pose = Pose {
                    position: Vec3::new(c[0], c[1], c[2]),
                    // Saved from a unit quaternion: restored bit for bit, not renormalised.
                    orientation: Quat::new_unchecked(nalgebra::Quaternion::new(
                        c[3], c[4], c[5], c[6],
                    )),
                };
                let fixed = fixed_values(store);
                let same_scene = self.sim.as_ref().is_some_and(|s| {
                    s.built_from.len() == fixed.len()
                        && s.built_from.iter().zip(&fixed).all(|(a, b)| a.same_bits(b))
                });
                if same_scene {
                    let sim = self.sim.as_mut().expect("checked");
                    sim.world
                        .restore_state(world)
                        .map_err(|e| ModelError::error(e.to_string()))?;
                    sim.pose = pose;
                } else {
                    log.info(
                        "the state was saved with other fixed parameters: rebuilding the world",
                    );
                    let mut sim =
                        build(store, self.resources.as_deref(), log).map_err(ModelError::error)?;
                    sim.world
                        .restore_state(world)
                        .map_err(|e| ModelError::error(e.to_string()))?;
                    sim.pose = pose;
                    self.sim = Some(sim);
                }
                Ok(())
            }
            t => Err(bad(format!("unknown tag {t}"))),
        }
    }
}

/// `settle = true`: bring the freshly built world to static equilibrium under gravity
/// ([`World::settle`]); a failure is an error naming the cause.
fn settle(sim: &mut Sim, log: &Logger) -> Result<(), ModelError> {
    let report = sim.world.settle().map_err(|e| {
        ModelError::error(format!(
            "settle = true: the organ could not be brought to static equilibrium: {e}"
        ))
    })?;
    let body = sim
        .world
        .body(sim.body)
        .map_err(|e| ModelError::error(e.to_string()))?;
    log.info(&format!(
        "settled: {} Newton iterations (relative residual {:.2e}), {} relaxation steps, \
         largest speed {:.2e} m/s{}, largest displacement {:.4} m",
        report.newton_iterations,
        report.relative_residual,
        report.relaxation_steps,
        report.max_speed,
        if report.converged {
            ""
        } else {
            " (relaxation not converged)"
        },
        body.max_displacement()
    ));
    if !report.converged {
        log.warning(&format!(
            "settle: relaxation stopped after {} steps with particles still moving at {:.2e} m/s",
            report.relaxation_steps, report.max_speed
        ));
    }
    Ok(())
}

/// Run `n` world steps moving the tool from `from` to `to`; the mean force and torque.
fn run_steps(
    sim: &mut Sim,
    settings: &Settings,
    from: Pose,
    to: Pose,
    n: u64,
    log: &Logger,
) -> Result<(Vec3, Vec3), ModelError> {
    let solver = |e: Error| {
        match e {
        Error::Diverged(m) => ModelError::discard(format!(
            "the solver diverged ({m}); the step was rolled back, retry with a smaller step or stiffer parameters"
        )),
        e => ModelError::error(e.to_string()),
    }
    };
    if settings != sim.world.settings() {
        sim.world.set_settings(settings.clone()).map_err(solver)?;
    }
    let mut force = Vec3::zeros();
    let mut torque = Vec3::zeros();
    let mut clamped = false;
    for k in 1..=n {
        let pose = if k == n {
            to
        } else {
            Pose::interpolate(&from, &to, k as f64 / n as f64)
        };
        sim.world.set_tool_pose(sim.tool, pose).map_err(solver)?;
        let report = sim.world.step().map_err(solver)?;
        clamped |= report.substeps_clamped;
        let w = sim.world.tool(sim.tool).map_err(solver)?.wrench();
        force += w.force;
        torque += w.torque;
    }
    if clamped {
        log.warning(&format!(
            "internal step {} s needed more than max_substeps = {} solver substeps for stability; ran with the maximum",
            settings.dt, settings.max_substeps
        ));
    }
    Ok((force / n as f64, torque / n as f64))
}

/// Number of internal steps for a communication step `h` and largest internal step `max_dt`:
/// `ceil(h / max_dt)`, with ratios within 1e-9 of an integer rounded to it.
pub fn substeps(h: f64, max_dt: f64) -> Result<u64, String> {
    if !(max_dt.is_finite() && max_dt > 0.0) {
        return Err(format!("internal_step = {max_dt} s must be > 0"));
    }
    let ratio = h / max_dt;
    let nearest = ratio.round();
    let n = if (ratio - nearest).abs() <= 1e-9 * ratio.max(1.0) {
        nearest
    } else {
        ratio.ceil()
    };
    if n.is_nan() || n > 1.0e7 {
        return Err(format!(
            "communication step {h} s needs {n} internal steps of {max_dt} s (limit 1e7)"
        ));
    }
    Ok((n as u64).max(1))
}

/// The pose of the inputs, by the core's one conversion of raw poses
/// ([`Pose::from_components`]: finite, quaternion normalised, a zero or tiny one refused).
pub fn pose_from_inputs(store: &Store) -> Result<Pose, String> {
    let position = [vr::TOOL_PX, vr::TOOL_PY, vr::TOOL_PZ].map(|r| store.real(r));
    let quaternion = [vr::TOOL_QW, vr::TOOL_QX, vr::TOOL_QY, vr::TOOL_QZ].map(|r| store.real(r));
    Pose::from_components(position, quaternion).map_err(|e| {
        format!(
            "tool pose (tool_px, tool_py, tool_pz) = {position:?}, (tool_qw, tool_qx, tool_qy, \
             tool_qz) = {quaternion:?}: {e}; the quaternion must be finite and non-zero"
        )
    })
}

fn fixed_values(store: &Store) -> Vec<Value> {
    store
        .table()
        .iter()
        .filter(|v| v.causality == Parameter && v.variability == Fixed)
        .map(|v| store.get(v.vr).clone())
        .collect()
}

/// The world settings for the tunable parameters of `store` and internal step `dt`.
fn settings_from(store: &Store, base: &Settings, dt: f64) -> Settings {
    let mut s = base.clone();
    s.dt = dt;
    s.gravity = Vec3::new(
        store.real(vr::GRAVITY_X),
        store.real(vr::GRAVITY_Y),
        store.real(vr::GRAVITY_Z),
    );
    s.damping_mass = store.real(vr::DAMPING);
    s.volume_compliance = store.real(vr::VOLUME_COMPLIANCE);
    s.volume_constraints = store.boolean(vr::VOLUME_CONSTRAINTS);
    s.threads = store.integer(vr::THREADS).clamp(1, 64) as u32;
    s.elastic_scheme = match store.integer(vr::ELASTIC_SCHEME) {
        1 => ElasticScheme::PointBased,
        _ => ElasticScheme::Tetrahedra,
    };
    s.volume_scheme = match store.integer(vr::VOLUME_SCHEME) {
        1 => VolumeScheme::Tetrahedra,
        _ => VolumeScheme::DualCells,
    };
    s.damping_stiffness = store.real(vr::DAMPING_STIFFNESS);
    s.min_substeps = store.integer(vr::MIN_SUBSTEPS).clamp(1, 64) as u32;
    s.crushed_substeps = store.integer(vr::CRUSHED_SUBSTEPS).clamp(1, 64) as u32;
    s
}

/// The tool shape of the parameters.
fn tool_shape(store: &Store) -> ToolShape {
    let radius = store.real(vr::TOOL_RADIUS);
    let half_height = store.real(vr::TOOL_HALF_LENGTH);
    match store.integer(vr::TOOL_SHAPE) {
        1 => ToolShape::Capsule {
            half_height,
            radius,
        },
        2 => ToolShape::Cylinder {
            half_height,
            radius,
        },
        3 => ToolShape::Cuboid {
            half_extents: Vec3::new(radius, half_height, radius),
        },
        _ => ToolShape::Sphere { radius },
    }
}

/// Where the mesh parameter points: `None` for the embedded default organ.
pub fn mesh_path(mesh: &str, resources: Option<&Path>) -> Result<Option<PathBuf>, String> {
    if mesh.is_empty() {
        return Ok(None);
    }
    let p = Path::new(mesh);
    if p.is_absolute() {
        return Ok(Some(p.to_path_buf()));
    }
    match resources {
        Some(dir) => Ok(Some(dir.join(p))),
        None => Err(format!(
            "mesh \"{mesh}\" is relative but the FMU has no usable resource location"
        )),
    }
}

/// Build the world from the parameters and inputs of `store`.
fn build(store: &Store, resources: Option<&Path>, log: &Logger) -> Result<Sim, String> {
    let scale = store.real(vr::MESH_SCALE);
    let mesh_name = store.string(vr::MESH).to_string();
    let organ = match mesh_path(&mesh_name, resources)? {
        None => {
            let mut m = mesh::default_organ();
            for n in &mut m.nodes {
                *n *= scale;
            }
            m
        }
        Some(path) => mesh::load(&path, scale).map_err(|e| e.to_string())?.0,
    };
    let settings = settings_from(store, &Settings::default(), store.real(vr::INTERNAL_STEP));
    let e = |e: Error| e.to_string();
    let mut world = World::new(settings).map_err(e)?;
    let options = BodyOptions {
        material: Material {
            youngs_modulus: store.real(vr::YOUNGS_MODULUS),
            poisson_ratio: store.real(vr::POISSON_RATIO),
            density: store.real(vr::DENSITY),
        },
        ..BodyOptions::default()
    };
    let body =
        world.add_body_model(crate::shared_models::shared_model(&organ, &options).map_err(e)?);
    let min = Vec3::new(
        store.real(vr::FIXED_MIN_X),
        store.real(vr::FIXED_MIN_Y),
        store.real(vr::FIXED_MIN_Z),
    );
    let max = Vec3::new(
        store.real(vr::FIXED_MAX_X),
        store.real(vr::FIXED_MAX_Y),
        store.real(vr::FIXED_MAX_Z),
    );
    let fixed = if min.x <= max.x && min.y <= max.y && min.z <= max.z {
        world.fix_box(body, min, max).map_err(e)?
    } else {
        0
    };
    let pose = pose_from_inputs(store)?;
    let shape = tool_shape(store);
    let tool = world
        .add_tool(
            shape.clone(),
            pose,
            &ToolOptions {
                friction_static: store.real(vr::FRICTION_STATIC),
                friction_kinetic: store.real(vr::FRICTION_KINETIC),
                sample_spacing: None,
            },
        )
        .map_err(e)?;
    let puncture_force = store.real(vr::NEEDLE_PUNCTURE_FORCE);
    if puncture_force > 0.0 {
        let needle = NeedleOptions {
            puncture_force,
            friction_per_length: store.real(vr::NEEDLE_FRICTION),
            reach: None,
        };
        world.make_needle(tool, &needle).map_err(e)?;
    }
    let b = world.body(body).map_err(e)?;
    log.info(&format!(
        "world built: mesh \"{mesh_name}\" ({} nodes, {} tets, rest volume {:e} m3), {fixed} nodes fixed, tool {shape:?}",
        organ.nodes.len(),
        organ.tets.len(),
        b.rest_volume()
    ));
    if fixed == 0 && world.settings().gravity.norm() > 0.0 {
        log.warning("no node lies in the fixed box: the organ will fall under gravity");
    }
    Ok(Sim {
        world,
        body,
        tool,
        built_from: fixed_values(store),
        pose,
    })
}

fn write_outputs(
    store: &mut Store,
    sim: &Sim,
    force: Vec3,
    torque: Vec3,
) -> Result<(), ModelError> {
    let e = |e: Error| ModelError::error(e.to_string());
    let body = sim.world.body(sim.body).map_err(e)?;
    let wrench = sim.world.tool(sim.tool).map_err(e)?.wrench();
    let values = [
        (vr::FORCE_X, force.x),
        (vr::FORCE_Y, force.y),
        (vr::FORCE_Z, force.z),
        (vr::TORQUE_X, torque.x),
        (vr::TORQUE_Y, torque.y),
        (vr::TORQUE_Z, torque.z),
        (vr::VOLUME, body.volume()),
        (vr::VOLUME_RATIO, body.volume_ratio()),
        (vr::MAX_DISPLACEMENT, body.max_displacement()),
        (vr::MAX_PENETRATION, wrench.max_penetration),
    ];
    for (vr, v) in values {
        store.set_real(vr, v);
    }
    store.set_integer(vr::CONTACT_COUNT, wrench.contact_count as i32);
    let held = sim.world.grasped_count(sim.tool).map_err(e)?;
    store.set_integer(vr::GRASPED_COUNT, held as i32);
    let depth = match sim.world.needle_state(sim.tool) {
        Ok(state) => state.inserted_length,
        Err(_) => 0.0,
    };
    store.set_real(vr::NEEDLE_DEPTH, depth);
    Ok(())
}

/// Follow the `grasp` input: true and holding nothing grasps what is within reach now (default
/// grasp options), false releases. Stateless (the world's state carries the attachments), so
/// fmi2SetFMUstate needs nothing more.
fn apply_grasp(sim: &mut Sim, grasp: bool) -> Result<(), Error> {
    let held = sim.world.grasped_count(sim.tool)?;
    match (grasp, held) {
        (true, 0) => sim
            .world
            .grasp(sim.tool, &GraspOptions::default())
            .map(|_| ()),
        (false, n) if n > 0 => sim.world.release(sim.tool),
        _ => Ok(()),
    }
}

/// The `resources/scene.txt` written into the FMU: every parameter with its default value,
/// unit and meaning, human-readable.
pub fn scene_text() -> String {
    use std::fmt::Write;
    let mut s = String::from(
        "# TissueSim FMU: default scene (the start values of modelDescription.xml).\n\
         # The organ mesh is resources/organ.vtk (the embedded default organ, in metres).\n\
         # name = value [unit]  # meaning\n\n",
    );
    for v in VARIABLES {
        let (value, unit) = match (v.kind, v.start_value()) {
            (Kind::Real { unit, .. }, Value::Real(x)) => (format!("{x:?}"), unit),
            (_, Value::Integer(x)) => (x.to_string(), ""),
            (_, Value::Boolean(x)) => (x.to_string(), ""),
            (_, Value::String(x)) => (format!("\"{x}\""), ""),
            _ => unreachable!(),
        };
        if v.causality == Output {
            continue;
        }
        let unit = if unit.is_empty() {
            String::new()
        } else {
            format!(" [{unit}]")
        };
        let _ = writeln!(
            s,
            "{:<18} = {value}{unit}  # {} {}: {}",
            v.name,
            v.causality.as_str(),
            v.variability.as_str(),
            v.description
        );
    }
    s
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::fmi2::variables::check_table;

    #[test]
    fn table_is_consistent() {
        check_table(VARIABLES, UNITS).unwrap();
        assert_eq!(VARIABLES.len(), vr::IDENTIFIERS.len());
        // The value-reference constants are the variable names in upper case.
        for (v, id) in VARIABLES.iter().zip(vr::IDENTIFIERS) {
            assert_eq!(v.name.to_uppercase(), *id);
        }
        assert_eq!(VARIABLES[vr::SETTLE as usize].name, "settle");
    }

    /// The variables table of docs/FMU.md is the one generated from [`VARIABLES`]
    /// (regenerate it with `build-fmu --update-docs docs/FMU.md`).
    #[test]
    fn docs_table_is_generated_from_the_variables() {
        let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../docs/FMU.md");
        let docs = std::fs::read_to_string(&path).unwrap();
        let expected = crate::fmi2::docs::replace_table(&docs, &crate::docs_table()).unwrap();
        assert!(
            docs == expected,
            "{} has a stale variables table: run `cargo run -p tissuesim-fmu --bin build-fmu -- --update-docs docs/FMU.md`",
            path.display()
        );
    }

    #[test]
    fn substep_count() {
        assert_eq!(substeps(1e-3, 1e-3).unwrap(), 1);
        assert_eq!(substeps(0.01, 1e-3).unwrap(), 10);
        assert_eq!(substeps(0.0105, 1e-3).unwrap(), 11);
        assert_eq!(substeps(1e-4, 1e-3).unwrap(), 1);
        assert_eq!(substeps(0.1 + 0.2, 0.1).unwrap(), 3);
        assert!(substeps(1.0, 0.0).is_err());
        assert!(substeps(1e9, 1e-3).is_err());
    }

    #[test]
    fn interpolation() {
        let a = Pose::at(Vec3::new(0.0, 0.0, 0.0));
        let b = Pose {
            position: Vec3::new(1.0, 2.0, 3.0),
            orientation: Quat::from_axis_angle(&Vec3::y_axis(), std::f64::consts::PI),
        };
        let m = Pose::interpolate(&a, &b, 0.5);
        assert!((m.position - Vec3::new(0.5, 1.0, 1.5)).norm() < 1e-15);
        assert!((m.orientation.angle() - std::f64::consts::FRAC_PI_2).abs() < 1e-12);
        assert!(
            (Pose::interpolate(&a, &b, 1.0)
                .orientation
                .angle_to(&b.orientation))
                < 1e-12
        );
        // Antipodal quaternions (the same rotation) do not panic and stay put.
        let c = Pose {
            position: Vec3::zeros(),
            orientation: Quat::new_unchecked(-a.orientation.into_inner()),
        };
        assert!(Pose::interpolate(&a, &c, 0.3).orientation.angle() < 1e-12);
    }

    #[test]
    fn zero_quaternion_is_refused() {
        let mut store = Store::new(VARIABLES);
        assert!(pose_from_inputs(&store).is_ok());
        store.set_real(vr::TOOL_QW, 0.0);
        assert!(pose_from_inputs(&store).unwrap_err().contains("non-zero"));
        store.set_real(vr::TOOL_QZ, 2.0);
        let p = pose_from_inputs(&store).unwrap();
        assert!((p.orientation.quaternion().norm() - 1.0).abs() < 1e-15);
    }

    #[test]
    fn mesh_resolution() {
        let res = Path::new("/fmu/resources");
        assert_eq!(mesh_path("", Some(res)).unwrap(), None);
        assert_eq!(
            mesh_path("organ.vtk", Some(res)).unwrap(),
            Some(PathBuf::from("/fmu/resources/organ.vtk"))
        );
        assert_eq!(
            mesh_path("/abs/liver.msh", None).unwrap(),
            Some(PathBuf::from("/abs/liver.msh"))
        );
        assert!(mesh_path("organ.vtk", None).is_err());
    }
}

#[cfg(test)]
mod default_scene {
    use super::*;

    /// The start values fit the default organ: the probe lies in front of it (+z), clear of it,
    /// facing tissue; the fixed box holds the top ~15 % of its height.
    #[test]
    fn start_values_fit_the_default_organ() {
        let organ = mesh::default_organ();
        let (lo, hi) = organ.bounding_box();
        eprintln!(
            "default organ: {} nodes, bbox {lo:?} .. {hi:?}",
            organ.nodes.len()
        );
        let probe = Vec3::from(DEFAULT_TOOL_POSITION);
        let radius = 0.01;
        let clearance = organ
            .nodes
            .iter()
            .map(|n| (n - probe).norm())
            .fold(f64::MAX, f64::min)
            - radius;
        eprintln!("probe clearance {clearance} m");
        assert!(
            clearance > 0.005 && clearance < 0.03,
            "clearance {clearance}"
        );
        assert!(probe.z > hi.z);
        let behind = organ
            .nodes
            .iter()
            .filter(|n| ((n.x - probe.x).powi(2) + (n.y - probe.y).powi(2)).sqrt() < radius)
            .count();
        assert!(behind > 0, "no tissue behind the probe");
        let height = hi.y - lo.y;
        let fixed_fraction = (hi.y - DEFAULT_FIXED_MIN[1]) / height;
        eprintln!("fixed top fraction {fixed_fraction}");
        assert!((0.1..=0.2).contains(&fixed_fraction));
        for k in [0, 2] {
            assert!(DEFAULT_FIXED_MIN[k] < lo[k] && DEFAULT_FIXED_MAX[k] > hi[k]);
        }
        assert!(DEFAULT_FIXED_MAX[1] > hi.y);
    }
}
