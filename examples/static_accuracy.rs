//! Static small-strain accuracy against the committed FEM references (validation/reference):
//! the linear gravity sag `K u = m g` of the library's discretisation (the stiffness of the
//! energy the step integrates, sparse direct solve), relative L2 against P2 on the same mesh.
//!
//! ```text
//! cargo run --release --example static_accuracy -- [--neighbours K] [--hourglass C]
//!     [--nodal-volume] [--particles] [--tet-volumes] [--paper] [--plain-mls] [--audit] [--tet-schemes]
//!     [--nu 0.3,0.45,...] [SCENE ...]
//! ```
//! The reference is P2 (displacement) below ν 0.45 and Taylor–Hood (mixed P2/P1,
//! `*_th.csv`) from 0.45 up, where displacement-only P2 locks too (validation/README.md g).
//! Without options: the default settings (the elasticity on corotated linear tetrahedra, one
//! volume constraint per particle on its dual cell). `--particles`: the elasticity on the
//! paper's point-based particles (`ElasticScheme::PointBased`). `--tet-volumes`: one volume
//! constraint per tetrahedron (`VolumeScheme::Tetrahedra`). `--paper`: both, the paper's
//! method. `--nodal-volume`: no volume constraints (the elasticity carries λ).
//! `--tet-schemes` adds columns for tetrahedral discretisations on the same nodes (assembled
//! in `tet_schemes.rs`): linear tets (a check of the assembly against the reference's P1
//! column), linear tets with the volumetric energy on the nodes' dual cells (the average nodal
//! pressure tetrahedron), and face- and edge-smoothed shear with the same.
//! `--audit` adds, per scene, the solution's best-fit scale against P2 (> 1: too soft) and the
//! energy audit of `audit.rs`: the deviatoric energy of the P2 field as the particles see it,
//! over what linear tetrahedra see, for the surface, interior and fixed particles.
//! Scenes: `liver_1k6`, `liver_4k`, `liver_10k`, `organ_c0133`, `organ_c0095`, `organ_c0068`,
//! `kidney_gmsh`, `liver_gmsh` and their refinements `*_coarse`, `*_fine` (at each ν of `--nu`,
//! default 0.3 and 0.45), `cantilever`
//! (ν 0.3, and 0.45 when its reference exists).
//! A scene whose reference file is missing is reported and skipped.

#[path = "static_accuracy/audit.rs"]
mod audit;
#[path = "static_accuracy/tet_schemes.rs"]
mod tet_schemes;

use std::collections::HashMap;
use std::path::{Path, PathBuf};
use tissuesim::mesh::{self, TetMesh};
use tissuesim::{statics, Body, BodyOptions, Material, Real, Settings, Vec3, World};

type Res<T> = Result<T, Box<dyn std::error::Error>>;

fn repo() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

fn mesh_dir() -> PathBuf {
    std::env::var_os("TISSUESIM_MESHES")
        .map(PathBuf::from)
        .unwrap_or_else(|| repo().join("data/meshes"))
}

fn read_reference(path: &Path) -> Res<HashMap<usize, Vec3>> {
    let text = std::fs::read_to_string(path)?;
    let mut out = HashMap::new();
    for line in text.lines().skip(1) {
        let v: Vec<&str> = line.split(',').collect();
        if v.len() < 4 {
            continue;
        }
        out.insert(
            v[0].trim().parse()?,
            Vec3::new(
                v[1].trim().parse()?,
                v[2].trim().parse()?,
                v[3].trim().parse()?,
            ),
        );
    }
    Ok(out)
}

struct Scene {
    name: String,
    mesh: TetMesh,
    material: Material,
    g: Real,
    /// Fixed particles.
    fixed: Vec<u32>,
    /// Node id of each particle in the reference CSV.
    ids: Vec<usize>,
    reference: PathBuf,
    p1: PathBuf,
}

fn top_fixed(mesh: &TetMesh) -> Vec<u32> {
    let (lo, hi) = mesh.bounding_box();
    let thr = hi.y - 0.1 * (hi.y - lo.y);
    (0..mesh.nodes.len() as u32)
        .filter(|&i| mesh.nodes[i as usize].y >= thr)
        .collect()
}

fn liver_material(nu: Real) -> Material {
    Material {
        youngs_modulus: 3000.0,
        poisson_ratio: nu,
        density: 1.0,
    }
}

/// The reference files' tag of a Poisson ratio: `nu030`, `nu045`, `nu049`, `nu0499`.
fn nu_tag(nu: Real) -> String {
    let digits = format!("{nu}");
    let fraction = digits.trim_start_matches("0.");
    format!("nu0{fraction:0<2}")
}

fn scenes(names: &[String], ratios: &[Real]) -> Res<Vec<Scene>> {
    let refdir = repo().join("validation/reference");
    let mut out = Vec::new();
    for name in names {
        for &nu in ratios {
            let tag = nu_tag(nu);
            let (mesh, prefix) = if let Some(rest) = name.strip_prefix("organ_c") {
                let cell: Real = format!("0.{rest}").parse()?;
                let mut m = mesh::organ_with_cell(cell);
                m.nodes.iter_mut().for_each(|p| *p *= 30.0);
                (m, format!("organ_c{rest}_{tag}"))
            } else if name == "cantilever" {
                let m = mesh::lattice_box(
                    Vec3::new(0.0, -0.01, -0.01),
                    Vec3::new(0.1, 0.01, 0.01),
                    [20, 4, 4],
                );
                let prefix = if nu == 0.3 {
                    "cantilever".to_string()
                } else {
                    "cantilever_nu045".to_string()
                };
                (m, prefix)
            } else if name.contains("_gmsh") {
                let m = mesh::load(&mesh_dir().join(format!("{name}.node")), 1.0)?.0;
                (m, format!("{name}_{tag}"))
            } else {
                let m = mesh::load(&mesh_dir().join(format!("{name}.node")), 1.0)?.0;
                (m, format!("{}_{tag}", name.replace('_', "")))
            };
            let (reference, p1) = if name == "cantilever" {
                (
                    refdir.join(format!("{prefix}_p2_lattice.csv")),
                    refdir.join(format!("{prefix}_p1_lattice.csv")),
                )
            } else if nu >= 0.45 {
                // Taylor–Hood (mixed P2/P1) from ν 0.45 up: displacement-only P2 locks there.
                (
                    refdir.join(format!("{prefix}_th.csv")),
                    refdir.join(format!("{prefix}_p1.csv")),
                )
            } else {
                (
                    refdir.join(format!("{prefix}_p2.csv")),
                    refdir.join(format!("{prefix}_p1.csv")),
                )
            };
            let (material, g, fixed, ids) = if name == "cantilever" {
                let ids = mesh
                    .nodes
                    .iter()
                    .map(|p| {
                        let c = |v: Real, lo: Real| ((v - lo) / 0.005).round() as usize;
                        c(p.x, 0.0) + 21 * (c(p.y, -0.01) + 5 * c(p.z, -0.01))
                    })
                    .collect();
                let fixed = (0..mesh.nodes.len() as u32)
                    .filter(|&i| mesh.nodes[i as usize].x < 1e-12)
                    .collect();
                let material = Material {
                    youngs_modulus: 5.0e4,
                    poisson_ratio: nu,
                    density: 1000.0,
                };
                (material, 9.81, fixed, ids)
            } else {
                let fixed = top_fixed(&mesh);
                (
                    liver_material(nu),
                    0.981,
                    fixed,
                    (0..mesh.nodes.len()).collect(),
                )
            };
            out.push(Scene {
                name: format!("{name} nu {nu}"),
                mesh,
                material,
                g,
                fixed,
                ids,
                reference,
                p1,
            });
        }
    }
    Ok(out)
}

fn rel_l2(u: &[Vec3], ids: &[usize], reference: &HashMap<usize, Vec3>) -> Res<Real> {
    let (mut e, mut n) = (0.0, 0.0);
    for (i, ui) in u.iter().enumerate() {
        let r = reference
            .get(&ids[i])
            .ok_or_else(|| format!("node {} missing from the reference", ids[i]))?;
        e += (ui - r).norm_squared();
        n += r.norm_squared();
    }
    Ok((e / n).sqrt())
}

/// The best-fit scale of `u` against the reference and the energy audit of the reference field.
/// `ids`: the reference node id of each particle.
fn print_audit(body: &Body, u: &[Vec3], ids: &[usize], reference: &HashMap<usize, Vec3>) {
    let r: Vec<Vec3> = ids.iter().map(|k| reference[k]).collect();
    let dot = |a: &[Vec3], b: &[Vec3]| a.iter().zip(b).map(|(p, q)| p.dot(q)).sum::<Real>();
    let scale = dot(u, &r) / dot(&r, &r);
    let a = audit::audit(body, &r);
    let ratio = |c: audit::ClassEnergy| c.particles / c.linear_tets;
    println!(
        "    scale {scale:.3}; P2 field's deviatoric energy, particles / linear tets: \
         surface {:.2}, interior {:.2}, fixed {:.2}",
        ratio(a.surface),
        ratio(a.interior),
        ratio(a.fixed)
    );
}

fn main() -> Res<()> {
    let mut args = std::env::args().skip(1);
    let mut options = BodyOptions::default();
    let mut settings = Settings::default();
    let mut names = Vec::new();
    let mut with_audit = false;
    let mut with_schemes = false;
    let mut ratios = vec![0.3, 0.45];
    while let Some(a) = args.next() {
        match a.as_str() {
            "--nu" => {
                let list = args.next().ok_or("--nu needs a list, e.g. 0.45,0.49")?;
                ratios = list
                    .split(',')
                    .map(|v| v.trim().parse())
                    .collect::<Result<_, _>>()?;
            }
            "--neighbours" => options.target_neighbours = args.next().ok_or("K")?.parse()?,
            "--hourglass" => settings.hourglass_stiffness = args.next().ok_or("C")?.parse()?,
            "--nodal-volume" => settings.volume_constraints = false,
            "--particles" => settings.elastic_scheme = tissuesim::ElasticScheme::PointBased,
            "--tet-volumes" => settings.volume_scheme = tissuesim::VolumeScheme::Tetrahedra,
            "--paper" => {
                settings.elastic_scheme = tissuesim::ElasticScheme::PointBased;
                settings.volume_scheme = tissuesim::VolumeScheme::Tetrahedra;
            }
            "--plain-mls" => options.consistent_gradients = false,
            "--audit" => with_audit = true,
            "--tet-schemes" => with_schemes = true,
            s => names.push(s.to_string()),
        }
    }
    if names.is_empty() {
        names = ["liver_1k6", "liver_4k", "organ_c0095", "cantilever"]
            .map(String::from)
            .to_vec();
    }
    if with_schemes {
        println!(
            "scene | tissuesim vs reference | P1 vs reference | P1 assembled here | \
             tets + dual cells | faces + dual cells | edges + dual cells"
        );
    } else {
        println!("scene | tissuesim vs reference | P1 vs reference");
    }
    for scene in scenes(&names, &ratios)? {
        let Ok(reference) = read_reference(&scene.reference) else {
            println!(
                "{} | no reference ({})",
                scene.name,
                scene.reference.display()
            );
            continue;
        };
        let mut s = settings.clone();
        s.gravity = Vec3::new(0.0, -scene.g, 0.0);
        let mut world = World::new(s)?;
        let o = BodyOptions {
            material: scene.material,
            ..options.clone()
        };
        let id = world.add_body(&scene.mesh, &o)?;
        // The scene names mesh nodes; the body works in its particle order.
        let order = world.body(id)?.particle_order().clone();
        let fixed = order
            .particles_of(&scene.fixed)
            .ok_or("fixed node out of range")?;
        world.fix_particles(id, &fixed)?;
        let ids = order.to_particle_order(&scene.ids);
        let body = world.body(id)?;
        let u = statics::linear_gravity_sag(body, Vec3::new(0.0, -scene.g, 0.0))?;
        let e = rel_l2(&u, &ids, &reference)?;
        let p1 = read_reference(&scene.p1)
            .ok()
            .and_then(|p1| {
                let u1: Vec<Vec3> = scene.ids.iter().map(|k| p1[k]).collect();
                rel_l2(&u1, &scene.ids, &reference).ok()
            })
            .map(|v| format!("{:.1}%", 100.0 * v))
            .unwrap_or_else(|| "-".into());
        let mut line = format!("{} | {:.1}% | {p1}", scene.name, 100.0 * e);
        if with_schemes {
            use tet_schemes::{Shear, Volumetric};
            for (shear, volumetric) in [
                (Shear::Tets, Volumetric::Tets),
                (Shear::Tets, Volumetric::DualCells),
                (Shear::Faces, Volumetric::DualCells),
                (Shear::Edges, Volumetric::DualCells),
            ] {
                let u = tet_schemes::linear_sag(
                    &scene.mesh,
                    &scene.fixed,
                    scene.material,
                    scene.g,
                    shear,
                    volumetric,
                )?;
                line += &format!(" | {:.1}%", 100.0 * rel_l2(&u, &scene.ids, &reference)?);
            }
        }
        println!("{line}");
        if with_audit {
            print_audit(body, &u, &ids, &reference);
        }
    }
    Ok(())
}
