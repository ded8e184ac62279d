//! The per-step divergence check: a body whose particles became non-finite, or left the
//! physical bounds of [`DivergenceLimits`] (a finite explosion), makes the step fail and be
//! rolled back. O(particles + boundary triangles) per body (the volume is that the boundary
//! encloses).
//!
//! The extent and volume bounds fail a step only when it moves the body farther out of them
//! than it was at the start of the step (`before`, its positions then): a body set into an inverted or
//! flattened state on purpose recovers through states outside the volume range, and each of
//! those steps brings it closer.

use crate::kernels::math::{is_finite_vec, Real, Vec3};
use crate::scene::body::{volume_of, Body};
use crate::scene::settings::DivergenceLimits;

/// The particle half of the check over a run of particles: the first particle that is
/// non-finite or too fast, and the bounding box (m) of the particles before it. Made in the
/// step's last update pass, one run per thread; runs merged in order ([`ParticleScan::then`])
/// give what one scan of the whole body gives.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct ParticleScan {
    failure: Option<(usize, ParticleFailure)>,
    lo: Vec3,
    hi: Vec3,
}

/// Why a particle fails the check.
#[derive(Debug, Clone, Copy, PartialEq)]
enum ParticleFailure {
    NonFinite,
    /// Its speed (m/s).
    TooFast(Real),
}

impl ParticleScan {
    /// Nothing scanned yet.
    pub(crate) const EMPTY: ParticleScan = ParticleScan {
        failure: None,
        lo: Vec3::new(Real::INFINITY, Real::INFINITY, Real::INFINITY),
        hi: Vec3::new(-Real::INFINITY, -Real::INFINITY, -Real::INFINITY),
    };

    /// Take particle `i` at `x` (m) moving at `v` (m/s) into the scan, against the speed limit
    /// `max_speed` (m/s); nothing after the first failure.
    #[inline]
    pub(crate) fn visit(&mut self, i: usize, x: &Vec3, v: &Vec3, max_speed: Real) {
        if self.failure.is_some() {
            return;
        }
        if !is_finite_vec(x) || !is_finite_vec(v) {
            self.failure = Some((i, ParticleFailure::NonFinite));
            return;
        }
        // The square root only near the limit: below a quarter of its square, the speed is
        // below half the limit whatever the rounding.
        if v.norm_squared() > 0.25 * max_speed * max_speed {
            let speed = v.norm();
            if speed > max_speed {
                self.failure = Some((i, ParticleFailure::TooFast(speed)));
                return;
            }
        }
        self.lo = self.lo.inf(x);
        self.hi = self.hi.sup(x);
    }

    /// This scan followed by the scan of the particles after it.
    pub(crate) fn then(&self, later: &ParticleScan) -> ParticleScan {
        if self.failure.is_some() {
            return *self;
        }
        ParticleScan {
            failure: later.failure,
            lo: self.lo.inf(&later.lo),
            hi: self.hi.sup(&later.hi),
        }
    }
}

/// Why `body` has diverged, or `None` when it is within `limits`; `scan` is the scan of all its
/// particles in their state now and `volume_ratio` its [`Body::volume_ratio`] (dimensionless),
/// `before` holds its positions (m) at the start of the step.
pub(crate) fn diverged(
    body: &Body,
    scan: &ParticleScan,
    volume_ratio: Real,
    before: &[Vec3],
    limits: &DivergenceLimits,
) -> Option<String> {
    let size = body.model.size;
    match scan.failure {
        Some((i, ParticleFailure::NonFinite)) => {
            return Some(format!("particle {i} became non-finite"));
        }
        Some((i, ParticleFailure::TooFast(speed))) => {
            return Some(format!(
                "particle {i} moves at {speed:.3e} m/s, above the limit of {:.3e} m/s \
                 ({} body sizes per second)",
                max_speed(body, limits),
                limits.max_speed
            ));
        }
        None => {}
    }
    let extent = (scan.hi - scan.lo).norm() / size;
    if extent > limits.max_extent_ratio && extent > extent_of(before) / size {
        return Some(format!(
            "the body spans {extent:.3e} times its rest size (limit {})",
            limits.max_extent_ratio
        ));
    }
    let (min_ratio, max_ratio) = limits.volume_ratio;
    let ratio_before = || volume_of(before, &body.model.boundary) / body.model.rest_volume;
    if (volume_ratio < min_ratio && volume_ratio < ratio_before())
        || (volume_ratio > max_ratio && volume_ratio > ratio_before())
    {
        return Some(format!(
            "its volume is {volume_ratio:.3e} times the rest volume (accepted [{min_ratio}, {max_ratio}])"
        ));
    }
    None
}

/// The speed limit (m/s) of `body`: `limits.max_speed` body sizes per second.
pub(crate) fn max_speed(body: &Body, limits: &DivergenceLimits) -> Real {
    limits.max_speed * body.model.size
}

/// Diagonal of the bounding box of `x` (m).
fn extent_of(x: &[Vec3]) -> Real {
    let (lo, hi) = x.iter().fold(
        (Vec3::repeat(Real::INFINITY), Vec3::repeat(-Real::INFINITY)),
        |(lo, hi), p| (lo.inf(p), hi.sup(p)),
    );
    (hi - lo).norm()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The scan of the particles `first..` at `x` moving at `v`.
    fn scan(first: usize, x: &[Vec3], v: &[Vec3], max_speed: Real) -> ParticleScan {
        let mut scan = ParticleScan::EMPTY;
        for (i, (x, v)) in x.iter().zip(v).enumerate() {
            scan.visit(first + i, x, v, max_speed);
        }
        scan
    }

    /// Scans of consecutive runs merged in order give the scan of the whole: the same first
    /// failure (a NaN, a particle too fast, or both at different places) and the same box,
    /// wherever the runs are split.
    #[test]
    fn runs_merged_in_order_give_the_whole_scan() {
        let n = 40;
        let x: Vec<Vec3> = (0..n)
            .map(|i| Vec3::new((i * 7 % 11) as Real, -(i as Real), (i % 3) as Real * 0.5))
            .collect();
        let v: Vec<Vec3> = (0..n)
            .map(|i| Vec3::new(0.1 * i as Real, 0.0, 0.0))
            .collect();
        let max_speed = 10.0;
        let mut cases = vec![(x.clone(), v.clone())];
        for (bad, fast) in [(Some(25), None), (None, Some(12)), (Some(30), Some(8))] {
            let (mut x, mut v) = (x.clone(), v.clone());
            if let Some(i) = bad {
                x[i].y = Real::NAN;
            }
            if let Some(i) = fast {
                v[i].z = -20.0;
            }
            cases.push((x, v));
        }
        for (x, v) in &cases {
            let whole = scan(0, x, v, max_speed);
            for split in [0, 1, 8, 12, 13, 25, 26, 39, 40] {
                let a = scan(0, &x[..split], &v[..split], max_speed);
                let b = scan(split, &x[split..], &v[split..], max_speed);
                assert_eq!(a.then(&b), whole, "split at {split}");
            }
        }
        assert_eq!(scan(0, &cases[0].0, &cases[0].1, max_speed).failure, None);
        assert_eq!(
            scan(0, &cases[1].0, &cases[1].1, max_speed).failure,
            Some((25, ParticleFailure::NonFinite))
        );
        assert_eq!(
            scan(0, &cases[2].0, &cases[2].1, max_speed).failure,
            Some((12, ParticleFailure::TooFast(cases[2].1[12].norm())))
        );
        assert_eq!(
            scan(0, &cases[3].0, &cases[3].1, max_speed).failure,
            Some((8, ParticleFailure::TooFast(cases[3].1[8].norm())))
        );
    }
}
