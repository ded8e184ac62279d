//! The render surface: a visual OBJ (liver-smooth.obj) bound to the
//! simulation mesh (liver.msh, same frame) follows the particles: an affine motion of the
//! particles moves every bound vertex, inside or outside the tetrahedra, by exactly that map;
//! normals rotate with a rotation; the binding finds the enclosing (or nearest) tetrahedron;
//! OBJ errors name the file and line; OBJ and VTU export.

mod common;

use common::mesh_path;
use parry3d_f64::math::Point;
use parry3d_f64::query::PointQuery;
use parry3d_f64::shape::Tetrahedron;
use std::path::PathBuf;
use tissuesim::render::{read_obj, write_obj, RenderMesh, INSIDE_TOLERANCE};
use tissuesim::{
    mesh, BodyId, BodyOptions, Error, Mat3, Real, RenderSurfaceId, Settings, Vec3, World,
};

/// SOFA's liver in metres (scale 0.03, as in the README) with its visual surface bound.
fn liver_world() -> (World, BodyId, RenderSurfaceId) {
    let (liver, _) = mesh::load(&mesh_path("liver.msh"), 0.03).unwrap();
    let mut world = World::new(Settings::default()).unwrap();
    let body = world.add_body(&liver, &BodyOptions::default()).unwrap();
    let visual = read_obj(&mesh_path("liver-smooth.obj"), 0.03).unwrap();
    let surface = world.add_render_surface(body, visual).unwrap();
    (world, body, surface)
}

/// Move every particle of `body` to `a x + b` (x its rest position), at rest.
fn move_affinely(world: &mut World, body: BodyId, a: &Mat3, b: &Vec3) {
    let rest = world.body(body).unwrap().rest_positions().to_vec();
    let x: Vec<Vec3> = rest.iter().map(|p| a * p + b).collect();
    let v = vec![Vec3::zeros(); x.len()];
    world.set_body_state(body, &x, &v).unwrap();
}

fn scratch(name: &str) -> PathBuf {
    let dir = PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join("render_surface");
    std::fs::create_dir_all(&dir).unwrap();
    dir.join(name)
}

#[test]
fn affine_motion_moves_every_vertex_by_that_map() {
    let (mut world, body, id) = liver_world();
    let report = *world.render_surface(id).unwrap().bind_report();
    println!("{report:?}");
    assert!(report.inside > 0 && report.outside > 0, "{report:?}");
    // A general affine map: rotation, anisotropic stretch, shear, translation.
    let r = nalgebra::Rotation3::from_euler_angles(0.3, -0.7, 1.1).into_inner();
    let a = r * Mat3::new(1.3, 0.2, 0.0, 0.0, 0.8, -0.1, 0.05, 0.0, 1.1);
    let b = Vec3::new(0.05, -0.2, 0.11);
    move_affinely(&mut world, body, &a, &b);
    let s = world.update_render_surface(id).unwrap();
    let rest = &s.mesh().positions;
    let size = (rest.iter().map(|p| p.norm()).fold(0.0, Real::max)) * a.norm() + b.norm();
    let (mut worst_in, mut worst_out) = (0.0 as Real, 0.0 as Real);
    for ((p, x), bind) in rest.iter().zip(s.positions()).zip(s.bindings()) {
        let e = (x - (a * p + b)).norm() / size;
        let inside = bind.weights.iter().all(|&w| w >= -INSIDE_TOLERANCE);
        if inside {
            worst_in = worst_in.max(e);
        } else {
            worst_out = worst_out.max(e);
        }
    }
    println!("largest relative error: inside {worst_in:.1e}, outside {worst_out:.1e}");
    assert!(
        worst_in < 1e-12 && worst_out < 1e-12,
        "{worst_in} {worst_out}"
    );
}

#[test]
fn normals_rotate_with_a_rotation() {
    let (mut world, body, id) = liver_world();
    let before = world.update_render_surface(id).unwrap().normals().to_vec();
    assert!(before.iter().all(|n| (n.norm() - 1.0).abs() < 1e-12));
    let r = nalgebra::Rotation3::from_euler_angles(-0.4, 0.9, 2.0).into_inner();
    move_affinely(&mut world, body, &r, &Vec3::new(0.3, 0.1, -0.2));
    let after = world.update_render_surface(id).unwrap().normals();
    let worst = before
        .iter()
        .zip(after)
        .map(|(n0, n)| (r * n0 - n).norm())
        .fold(0.0, Real::max);
    assert!(worst < 1e-12, "largest normal error {worst}");
}

#[test]
fn rest_normals_agree_with_the_file_normals() {
    let (world, _, id) = liver_world();
    let s = world.render_surface(id).unwrap();
    let dots: Vec<Real> = s
        .normals()
        .iter()
        .zip(&s.mesh().normals)
        .map(|(n, f)| n.dot(f))
        .collect();
    let mean = dots.iter().sum::<Real>() / dots.len() as Real;
    let opposed = dots.iter().filter(|&&d| d < 0.0).count();
    println!(
        "mean cos(recomputed, file) {mean:.4}, {opposed} of {} opposed",
        dots.len()
    );
    assert!(
        mean > 0.9,
        "recomputed normals disagree with the file's: mean cos {mean}"
    );
}

#[test]
fn binding_gives_every_vertex_its_enclosing_or_nearest_tet() {
    let (world, body, id) = liver_world();
    let b = world.body(body).unwrap();
    let s = world.render_surface(id).unwrap();
    let (rest, tets) = (b.rest_positions(), b.tets());
    let report = s.bind_report();
    assert_eq!(report.inside + report.outside, s.vertex_count());
    let mut outside = 0;
    let mut max_distance: Real = 0.0;
    for (p, bind) in s.mesh().positions.iter().zip(s.bindings()) {
        assert!((bind.tet as usize) < tets.len());
        assert_eq!(bind.nodes, tets[bind.tet as usize]);
        let sum: Real = bind.weights.iter().sum();
        assert!((sum - 1.0).abs() < 1e-12, "weights sum to {sum}");
        assert!(
            (bind.apply(rest) - p).norm() < 1e-12,
            "weights reproduce the rest point"
        );
        let corners = |t: &[u32; 4]| t.map(|i| Point::from(rest[i as usize]));
        // Brute force over every tetrahedron: the distance to the nearest one.
        let nearest = tets
            .iter()
            .map(|t| {
                let [a, b, c, d] = corners(t);
                Tetrahedron::new(a, b, c, d).distance_to_local_point(&Point::from(*p), true)
            })
            .fold(Real::MAX, Real::min);
        let [ta, tb, tc, td] = corners(&bind.nodes);
        let own = Tetrahedron::new(ta, tb, tc, td).distance_to_local_point(&Point::from(*p), true);
        if bind.weights.iter().all(|&w| w >= -INSIDE_TOLERANCE) {
            assert!(bind.weights.iter().all(|&w| w <= 1.0 + INSIDE_TOLERANCE));
            assert!(own < 1e-12);
        } else {
            outside += 1;
            assert!(
                nearest > 0.0,
                "a vertex inside a tetrahedron was bound as outside"
            );
            assert!(
                own - nearest < 1e-15,
                "not the nearest tet: {own} > {nearest}"
            );
            max_distance = max_distance.max(own);
        }
    }
    assert_eq!(outside, report.outside);
    assert!((max_distance - report.max_outside_distance).abs() < 1e-15);
}

#[test]
fn boundary_surface_of_a_body_is_bound_inside() {
    let organ = mesh::lattice_box(Vec3::repeat(-0.05), Vec3::repeat(0.05), [4, 3, 5]);
    let mut world = World::new(Settings::default()).unwrap();
    let body = world.add_body(&organ, &BodyOptions::default()).unwrap();
    let b = world.body(body).unwrap();
    let surface = RenderMesh::from_boundary(b.rest_positions(), b.boundary_triangles());
    assert_eq!(surface.triangles.len(), b.boundary_triangles().len());
    let id = world.add_render_surface(body, surface).unwrap();
    let s = world.render_surface(id).unwrap();
    assert_eq!(s.bind_report().outside, 0);
    let rest = world.body(body).unwrap().rest_positions();
    for (p, src) in s.positions().iter().zip(&s.mesh().sources) {
        assert!((p - rest[src.position as usize]).norm() < 1e-15);
    }
    // The outward normals of a box's faces: on the +x face, away from the edges, +x.
    for (p, n) in s.positions().iter().zip(s.normals()) {
        if (p.x - 0.05).abs() < 1e-12 && p.y.abs() < 0.049 && p.z.abs() < 0.049 {
            assert!((n - Vec3::x()).norm() < 1e-12, "{n:?}");
        }
    }
}

#[test]
fn unknown_ids_are_errors() {
    let (mut world, _, _) = liver_world();
    assert_eq!(
        world.render_surface(RenderSurfaceId(7)).unwrap_err(),
        Error::UnknownRenderSurface(7)
    );
    assert_eq!(
        world.update_render_surface(RenderSurfaceId(1)).unwrap_err(),
        Error::UnknownRenderSurface(1)
    );
    let visual = read_obj(&mesh_path("liver-smooth.obj"), 0.03).unwrap();
    assert_eq!(
        world.add_render_surface(BodyId(3), visual).unwrap_err(),
        Error::UnknownBody(3)
    );
    assert_eq!(world.render_surface_count(), 1);
}

/// Write `text` to a scratch OBJ file and read it.
fn read_text(name: &str, text: &str) -> (PathBuf, Result<RenderMesh, mesh::MeshError>) {
    let path = scratch(name);
    std::fs::write(&path, text).unwrap();
    let r = read_obj(&path, 1.0);
    (path, r)
}

#[test]
fn obj_errors_name_file_and_line() {
    let head = "# a quad\nv 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nvt 0 0\nvn 0 0 1\n";
    let cases = [
        ("f 1/1/1 2/1/1 3/2/1\n", 8, "texture coordinate index 2"),
        ("f 1//1 2//2 3//1\n", 8, "normal index 2"),
        ("f 1 2 5\n", 8, "vertex index 5"),
        ("f 1 2\n", 8, "at least 3"),
        ("f 0 1 2\n", 8, "index 0"),
        ("f 1/x 2 3\n", 8, "invalid texture coordinate index"),
        ("f 1/1/1/1 2 3\n", 8, "invalid face corner"),
        ("vt 0.5 nan\n", 8, "texture coordinate v"),
        ("\nvn 0 1\n", 9, "missing z"),
        ("f -9 1 2\n", 8, "relative vertex index -9"),
    ];
    for (k, (tail, line, what)) in cases.iter().enumerate() {
        let (path, r) = read_text(&format!("bad_{k}.obj"), &format!("{head}{tail}"));
        let e = r.unwrap_err();
        assert_eq!(e.path, path, "{e}");
        assert_eq!(e.line, Some(*line), "{e}");
        assert!(e.message.contains(what), "{e}");
        assert!(
            e.to_string()
                .starts_with(&format!("{}:{line}:", path.display())),
            "{e}"
        );
    }
    let missing = scratch("missing.obj");
    let e = read_obj(&missing, 1.0).unwrap_err();
    assert_eq!(e.path, missing);
}

#[test]
fn obj_vertices_are_distinct_triples_and_polygons_are_fans() {
    let text = "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\n\
                vt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\nvt 0.5\nvn 0 0 2\n\
                f 1/1/1 2/2/1 3/3/1 4/4/1\n\
                f 1/5 3/3 2/2\n\
                f 4//1 -3//-1 -1//-1\n\
                f 1 2 4\n";
    let (_, r) = read_text("forms.obj", text);
    let m = r.unwrap();
    // (1,1,1) (2,2,1) (3,3,1) (4,4,1) | (1,5,-) (3,3,-) (2,2,-) | (4,-,1) (2,-,1) | (1,-,-)
    // (2,-,-) (4,-,-): 12 distinct triples; the quad gives 2 triangles.
    assert_eq!(m.vertex_count(), 12);
    assert_eq!(m.triangles.len(), 5);
    assert_eq!(m.triangles[0], [0, 1, 2]);
    assert_eq!(m.triangles[1], [0, 2, 3]);
    assert!(m.has_texcoords);
    assert_eq!(m.texcoords[4], [0.5, 0.0]);
    assert_eq!(m.normals[0], Vec3::z());
    assert_eq!(m.normals[4], Vec3::zeros());
    assert_eq!(m.sources[7].position, 3);
    assert_eq!(m.sources[8].position, 1);
    assert_eq!(m.sources[8].normal, Some(0));
}

#[test]
fn obj_round_trip_of_the_deformed_surface() {
    let (mut world, body, id) = liver_world();
    let r = nalgebra::Rotation3::from_euler_angles(0.1, 0.2, 0.3).into_inner();
    move_affinely(&mut world, body, &(r * 1.1), &Vec3::new(0.0, 0.01, 0.0));
    let s = world.update_render_surface(id).unwrap();
    let path = scratch("liver_deformed.obj");
    s.write_obj(&path).unwrap();
    let back = read_obj(&path, 1.0).unwrap();
    assert_eq!(back.positions, s.positions());
    assert_eq!(back.triangles, s.triangles());
    assert_eq!(back.has_texcoords, s.mesh().has_texcoords);
    let worst = back
        .normals
        .iter()
        .zip(s.normals())
        .map(|(a, b)| (a - b).norm())
        .fold(0.0, Real::max);
    assert!(worst < 1e-15, "{worst}");

    // With texture coordinates: they survive the round trip bit for bit.
    let quad =
        "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nvt 0.125 0.25\nvt 0.75 0.5\nvt 1 1\nvt 0.1 0.3\n\
                vn 0 0 1\nf 1/1/1 2/2/1 3/3/1 4/4/1\n";
    let (_, m) = read_text("quad.obj", quad);
    let m = m.unwrap();
    let out = scratch("quad_out.obj");
    write_obj(
        &out,
        &m.positions,
        &m.normals,
        Some(&m.texcoords),
        &m.triangles,
    )
    .unwrap();
    let back = read_obj(&out, 1.0).unwrap();
    assert_eq!(back.positions, m.positions);
    assert_eq!(back.texcoords, m.texcoords);
    assert_eq!(back.normals, m.normals);
    assert_eq!(back.triangles, m.triangles);
}

#[test]
fn vtu_export_has_triangles_and_normals() {
    let (world, _, id) = liver_world();
    let s = world.render_surface(id).unwrap();
    let path = scratch("liver_surface.vtu");
    s.write_vtu(&path).unwrap();
    let text = std::fs::read_to_string(&path).unwrap();
    assert!(text.contains(&format!(
        "NumberOfPoints=\"{}\" NumberOfCells=\"{}\"",
        s.vertex_count(),
        s.triangles().len()
    )));
    assert!(text.contains("Name=\"Normals\" NumberOfComponents=\"3\""));
    let types = text.split("Name=\"types\"").nth(1).unwrap();
    let first = types.lines().nth(1).unwrap().trim();
    assert_eq!(first, "5");
}
