//! Linear sags of tetrahedral discretisations on the same nodes as the particles, for the
//! comparison that chooses the next default (docs/VALIDATION.md, "Which discretisation"):
//! the shear part `2μ ε:ε` integrated on the tetrahedra (P1), on face domains (FS-FEM: a
//! face's two tetrahedra averaged) or on edge domains (ES-FEM: an edge's ring averaged), and
//! the volumetric part `λ (div u)²` on the tetrahedra (P1) or on each node's dual cell (a
//! quarter of each tetrahedron around it: the average nodal pressure of Bonet & Burton 1998,
//! one constraint per node). Lumped masses `ρ V_dual`, gravity, fixed nodes held; assembled
//! and solved here (sparse Cholesky), independent of the library's own statics.

use faer::linalg::solvers::Solve;
use faer::sparse::{SparseColMat, Triplet};
use faer::{Mat, Side};
use std::collections::HashMap;
use tissuesim::mesh::TetMesh;
use tissuesim::{Material, Real, Vec3};

/// Where the shear energy is integrated.
#[derive(Clone, Copy, PartialEq)]
pub enum Shear {
    Tets,
    Faces,
    Edges,
}

/// Where the volumetric energy is integrated.
#[derive(Clone, Copy, PartialEq)]
pub enum Volumetric {
    Tets,
    DualCells,
}

/// `V ∇N_a` (m²) of the four corners of tetrahedron `t` at the rest positions.
fn scaled_gradients(x: &[Vec3], t: &[u32; 4]) -> [Vec3; 4] {
    let [a, b, c, d] = t.map(|k| x[k as usize]);
    let gb = (c - a).cross(&(d - a)) / 6.0;
    let gc = (d - a).cross(&(b - a)) / 6.0;
    let gd = (b - a).cross(&(c - a)) / 6.0;
    [-(gb + gc + gd), gb, gc, gd]
}

/// Signed rest volume (m³) of tetrahedron `t`.
fn volume(x: &[Vec3], t: &[u32; 4]) -> Real {
    let [a, b, c, d] = t.map(|k| x[k as usize]);
    (b - a).cross(&(c - a)).dot(&(d - a)) / 6.0
}

/// A smoothing domain: its nodes, the smoothed gradient `∇N` (1/m) of each, its volume (m³).
struct Domain {
    nodes: Vec<u32>,
    gradient: Vec<Vec3>,
    volume: Real,
}

/// The domains made of the tetrahedra sharing a key (a face, an edge, or the tetrahedron
/// itself), each tetrahedron giving `share` of its volume to each of its keys.
fn domains(mesh: &TetMesh, keys: fn(&[u32; 4]) -> Vec<Vec<u32>>, share: Real) -> Vec<Domain> {
    let mut by_key: HashMap<Vec<u32>, Vec<usize>> = HashMap::new();
    for (t, tet) in mesh.tets.iter().enumerate() {
        for mut key in keys(tet) {
            key.sort_unstable();
            by_key.entry(key).or_default().push(t);
        }
    }
    let mut keys: Vec<_> = by_key.into_iter().collect();
    keys.sort();
    keys.into_iter()
        .map(|(_, tets)| smoothing_domain(mesh, &tets, share))
        .collect()
}

/// The domain made of the tetrahedra `tets`, each giving `share` of its volume: the
/// volume-weighted mean of their gradients over their nodes.
fn smoothing_domain(mesh: &TetMesh, tets: &[usize], share: Real) -> Domain {
    let mut nodes: Vec<u32> = tets.iter().flat_map(|&t| mesh.tets[t]).collect();
    nodes.sort_unstable();
    nodes.dedup();
    let mut gradient = vec![Vec3::zeros(); nodes.len()];
    let mut total = 0.0;
    for &t in tets {
        let tet = &mesh.tets[t];
        for (c, g) in scaled_gradients(&mesh.nodes, tet).iter().enumerate() {
            gradient[nodes.binary_search(&tet[c]).unwrap()] += g;
        }
        total += volume(&mesh.nodes, tet);
    }
    gradient.iter_mut().for_each(|g| *g /= total);
    Domain {
        nodes,
        gradient,
        volume: share * total,
    }
}

fn tet_keys(t: &[u32; 4]) -> Vec<Vec<u32>> {
    vec![t.to_vec()]
}

fn face_keys(t: &[u32; 4]) -> Vec<Vec<u32>> {
    (0..4)
        .map(|skip| (0..4).filter(|&c| c != skip).map(|c| t[c]).collect())
        .collect()
}

fn edge_keys(t: &[u32; 4]) -> Vec<Vec<u32>> {
    let mut out = Vec::new();
    for a in 0..4 {
        for b in a + 1..4 {
            out.push(vec![t[a], t[b]]);
        }
    }
    out
}

/// The dual cell of every node: the tetrahedra around it, each giving a quarter of its volume.
fn dual_cells(mesh: &TetMesh) -> Vec<Domain> {
    let n = mesh.nodes.len();
    let mut tets_of: Vec<Vec<usize>> = vec![Vec::new(); n];
    for (t, tet) in mesh.tets.iter().enumerate() {
        tet.iter().for_each(|&k| tets_of[k as usize].push(t));
    }
    (0..n)
        .map(|i| smoothing_domain(mesh, &tets_of[i], 0.25))
        .collect()
}

/// The linear sag (m, mesh node order) under gravity `g` (m/s², along −y) with `fixed` nodes
/// held, for the given integration of the shear and volumetric energies.
pub fn linear_sag(
    mesh: &TetMesh,
    fixed: &[u32],
    material: Material,
    g: Real,
    shear: Shear,
    volumetric: Volumetric,
) -> Result<Vec<Vec3>, String> {
    let e = material.youngs_modulus;
    let nu = material.poisson_ratio;
    let mu = e / (2.0 * (1.0 + nu));
    let lambda = e * nu / ((1.0 + nu) * (1.0 - 2.0 * nu));
    let n = mesh.nodes.len();
    let mut dof = vec![usize::MAX; n];
    let mut free = 0;
    let is_fixed: Vec<bool> = {
        let mut f = vec![false; n];
        fixed.iter().for_each(|&k| f[k as usize] = true);
        f
    };
    for i in 0..n {
        if !is_fixed[i] {
            dof[i] = free;
            free += 1;
        }
    }
    let mut triplets = Vec::new();
    let mut add = |p: u32, q: u32, block: [[Real; 3]; 3]| {
        let (dp, dq) = (dof[p as usize], dof[q as usize]);
        if dp == usize::MAX || dq == usize::MAX || dq > dp {
            return;
        }
        for (a, row) in block.iter().enumerate() {
            for (b, v) in row.iter().enumerate() {
                let (r, c) = (3 * dp + a, 3 * dq + b);
                if c <= r {
                    triplets.push(Triplet::new(r, c, *v));
                }
            }
        }
    };
    let shear_domains = match shear {
        Shear::Tets => domains(mesh, tet_keys, 1.0),
        Shear::Faces => domains(mesh, face_keys, 0.25),
        Shear::Edges => domains(mesh, edge_keys, 1.0 / 6.0),
    };
    // Shear: V μ [(∇N_p·∇N_q) I + ∇N_q ∇N_pᵀ].
    for d in &shear_domains {
        for (p, gp) in d.nodes.iter().zip(&d.gradient) {
            for (q, gq) in d.nodes.iter().zip(&d.gradient) {
                let mut block = [[0.0; 3]; 3];
                for (a, row) in block.iter_mut().enumerate() {
                    for (b, v) in row.iter_mut().enumerate() {
                        let identity = if a == b { gp.dot(gq) } else { 0.0 };
                        *v = d.volume * mu * (identity + gq[a] * gp[b]);
                    }
                }
                add(*p, *q, block);
            }
        }
    }
    // Volumetric: V λ ∇N_p ∇N_qᵀ.
    let volume_domains = match volumetric {
        Volumetric::Tets => domains(mesh, tet_keys, 1.0),
        Volumetric::DualCells => dual_cells(mesh),
    };
    for d in &volume_domains {
        for (p, gp) in d.nodes.iter().zip(&d.gradient) {
            for (q, gq) in d.nodes.iter().zip(&d.gradient) {
                let mut block = [[0.0; 3]; 3];
                for (a, row) in block.iter_mut().enumerate() {
                    for (b, v) in row.iter_mut().enumerate() {
                        *v = d.volume * lambda * gp[a] * gq[b];
                    }
                }
                add(*p, *q, block);
            }
        }
    }
    let m = 3 * free;
    let k = SparseColMat::<usize, Real>::try_new_from_triplets(m, m, &triplets)
        .map_err(|e| format!("assembly: {e:?}"))?;
    let llt = k
        .sp_cholesky(Side::Lower)
        .map_err(|_| "singular stiffness".to_string())?;
    // Lumped weights: ρ V_dual g.
    let mut rhs = Mat::<Real>::zeros(m, 1);
    for (i, cell) in dual_cells(mesh).iter().enumerate() {
        if dof[i] != usize::MAX {
            rhs[(3 * dof[i] + 1, 0)] = -material.density * cell.volume * g;
        }
    }
    llt.solve_in_place(rhs.as_mut());
    Ok((0..n)
        .map(|i| match dof[i] {
            usize::MAX => Vec3::zeros(),
            d => Vec3::new(rhs[(3 * d, 0)], rhs[(3 * d + 1, 0)], rhs[(3 * d + 2, 0)]),
        })
        .collect())
}
