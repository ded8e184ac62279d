//! Energy audit of a discretisation: the deviatoric (shear) strain energy the particles see in
//! a given displacement field, against linear tetrahedra on the same nodes, split by where the
//! particles are (free surface, interior, fixed). It locates where a discretisation is too
//! soft or too stiff for the reference solution, independently of the solve.

use tissuesim::{Body, Mat3, Real, Vec3};

/// Deviatoric energy (J) of one class of particles: as the particles see it, and as linear
/// tetrahedra see it with each tetrahedron's energy lumped ¼ to each corner.
#[derive(Default, Clone, Copy)]
pub struct ClassEnergy {
    pub particles: Real,
    pub linear_tets: Real,
}

/// The energies of the free surface particles, the interior particles and the fixed ones.
pub struct Audit {
    pub surface: ClassEnergy,
    pub interior: ClassEnergy,
    pub fixed: ClassEnergy,
}

/// `μ |dev ε|²` (Pa) of the small strain of displacement gradient `g`.
fn deviatoric_density(mu: Real, g: &Mat3) -> Real {
    let eps = (g + g.transpose()) * 0.5;
    let dev = eps - Mat3::identity() * (eps.trace() / 3.0);
    mu * dev.norm_squared()
}

/// Audit displacement field `u` (m, one per particle) on `body` at rest.
pub fn audit(body: &Body, u: &[Vec3]) -> Audit {
    let n = body.particle_count();
    let mu = body.material().shear_modulus();
    let nbr = body.neighbourhoods();
    let rest = body.rest_positions();
    let mut on_surface = vec![false; n];
    for t in body.boundary_triangles() {
        for &k in t {
            on_surface[k as usize] = true;
        }
    }
    let mut energy = vec![ClassEnergy::default(); n];
    for (i, e) in energy.iter_mut().enumerate() {
        // ∇u_i = Σ_j (u_j − u_i) g_ijᵀ, as the step's F.
        let g = nbr
            .range(i)
            .map(|p| (u[nbr.index[p] as usize] - u[i]) * nbr.gradient.get(p).transpose())
            .sum::<Mat3>();
        let volume = body.masses()[i] / body.material().density;
        e.particles = volume * deviatoric_density(mu, &g);
    }
    for tet in body.tets() {
        let x = tet.map(|k| rest[k as usize]);
        let edges = Mat3::from_columns(&[x[1] - x[0], x[2] - x[0], x[3] - x[0]]);
        let du = Mat3::from_columns(&[1, 2, 3].map(|c| u[tet[c] as usize] - u[tet[0] as usize]));
        let Some(inverse) = edges.try_inverse() else {
            continue;
        };
        let share = edges.determinant() / 24.0 * deviatoric_density(mu, &(du * inverse));
        for &k in tet {
            energy[k as usize].linear_tets += share;
        }
    }
    let mut out = Audit {
        surface: ClassEnergy::default(),
        interior: ClassEnergy::default(),
        fixed: ClassEnergy::default(),
    };
    for (i, e) in energy.iter().enumerate() {
        let class = if body.is_fixed(i) {
            &mut out.fixed
        } else if on_surface[i] {
            &mut out.surface
        } else {
            &mut out.interior
        };
        class.particles += e.particles;
        class.linear_tets += e.linear_tets;
    }
    out
}
