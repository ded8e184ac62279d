//! Hysteresis on the substep count: once the rules of [`Scene::substeps_needed`] raise the
//! count, it stays raised until they have asked for less for [`SUBSTEP_HOLD_STEPS`] steps in
//! a row.
//!
//! Why: one substep's kick and drift is stable at any fixed substep `h` up to `ω h < 2` for a
//! mode of angular frequency `ω` (rad/s), but a sequence of steps that mixes one substep of `h`
//! and two of `h / 2` is not. For the undamped mode the worst periodic pattern of such steps
//! grows by about 0.9 e-folds per drop of the count, at `ω h` near 1.8 (one substep at the
//! default `stability_margin` of 0.9 allows that): 0.32 e-folds a step when the count toggles
//! every step, 0.08 when it is held 8 steps, 0.007 when it is held 128 (computed in this
//! file's tests, which check the hold against it). A rule on a state near its threshold (a
//! crushed tetrahedron at a tool) can toggle every step, and a part of the organ far from the
//! tool then rings up until the step diverges (liver_1k6, a 2.5 mm probe pressed along +z:
//! `tests/contact_press_check.rs`). Held, a drop comes at most once per hold, and the material's
//! damping removes what it adds.
//!
//! The hold is part of the scene's state ([`crate::WorldState`]), so a restored state steps the
//! same as the original run.
//!
//! [`Scene::substeps_needed`]: crate::scene::Scene::substeps_needed

/// Steps (dimensionless) the substep count stays at its last raised value after the rules
/// ask for less: 128 steps (0.128 s at the default 1 ms step) bound the worst undamped growth
/// from switching to 0.007 e-folds a step.
pub const SUBSTEP_HOLD_STEPS: u32 = 128;

/// The substep count the last steps took and how long it is held.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub(crate) struct SubstepHold {
    /// The held count (0: none yet).
    pub(crate) count: u32,
    /// Steps (dimensionless) the count is still held for; 0 once the hold has run out.
    pub(crate) steps_left: u32,
}

impl SubstepHold {
    /// The count for a step whose rules ask for `asked` substeps: at least the held count while
    /// the hold lasts.
    pub(crate) fn count_for(&self, asked: u32) -> u32 {
        if self.steps_left > 0 {
            asked.max(self.count)
        } else {
            asked
        }
    }

    /// After a step of `taken` substeps whose rules asked for `asked`: the hold restarts at
    /// `taken` when the rules asked for it (or more), and runs down otherwise.
    pub(crate) fn advance(&mut self, asked: u32, taken: u32) {
        if asked >= taken {
            *self = SubstepHold {
                count: taken,
                steps_left: SUBSTEP_HOLD_STEPS,
            };
        } else {
            self.steps_left = self.steps_left.saturating_sub(1);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// One step of `n` substeps of kick and drift on the undamped mode `ẍ = −ω² x`, with
    /// `a = ω dt / n`, on the state (ω x, v): the drift after the kick.
    fn step_matrix(a: f64, n: u32) -> [[f64; 2]; 2] {
        let one = [[1.0 - a * a, a], [-a, 1.0]];
        (1..n).fold(one, |m, _| product(&one, &m))
    }

    fn product(a: &[[f64; 2]; 2], b: &[[f64; 2]; 2]) -> [[f64; 2]; 2] {
        let c = |i: usize, j: usize| a[i][0] * b[0][j] + a[i][1] * b[1][j];
        [[c(0, 0), c(0, 1)], [c(1, 0), c(1, 1)]]
    }

    /// The worst growth (e-folds a step) of the undamped mode over the periodic patterns of
    /// `low` steps of one substep after `held` steps of two, for `ω dt` up to 1.8 (one
    /// substep at the default stability margin). The matrices have determinant 1, so the
    /// spectral radius is `(|tr| + sqrt(tr² − 4)) / 2` when `|tr| > 2` and 1 otherwise.
    fn worst_growth(held: u32) -> f64 {
        let mut worst: f64 = 0.0;
        for i in 1..=180 {
            let a = 0.01 * i as f64;
            let two = step_matrix(a / 2.0, 2);
            let one = step_matrix(a, 1);
            for low in [1, 2, 3, 5, 8, 13] {
                let mut m = [[1.0, 0.0], [0.0, 1.0]];
                (0..held).for_each(|_| m = product(&two, &m));
                (0..low).for_each(|_| m = product(&one, &m));
                let tr = (m[0][0] + m[1][1]).abs();
                let radius = if tr > 2.0 {
                    (tr + (tr * tr - 4.0).sqrt()) / 2.0
                } else {
                    1.0
                };
                worst = worst.max(radius.ln() / (held + low) as f64);
            }
        }
        worst
    }

    #[test]
    fn the_hold_bounds_the_growth_from_switching() {
        assert!(worst_growth(1) > 0.3, "toggling every step grows fast");
        let held = worst_growth(SUBSTEP_HOLD_STEPS);
        assert!(
            held < 0.01,
            "held {SUBSTEP_HOLD_STEPS} steps: {held} e-folds a step"
        );
        // Fixed counts do not grow.
        assert_eq!(worst_growth(0), 0.0);
    }

    #[test]
    fn a_raised_count_is_held_then_dropped() {
        let mut hold = SubstepHold::default();
        assert_eq!(hold.count_for(1), 1);
        hold.advance(1, 1);
        assert_eq!(hold.count_for(2), 2);
        hold.advance(2, 2);
        for _ in 0..SUBSTEP_HOLD_STEPS {
            let n = hold.count_for(1);
            assert_eq!(n, 2, "dropped inside the hold");
            hold.advance(1, n);
        }
        assert_eq!(hold.count_for(1), 1, "held past the hold");
        hold.advance(1, 1);
        assert_eq!(hold.count_for(1), 1);
    }

    #[test]
    fn asking_again_restarts_the_hold() {
        let mut hold = SubstepHold::default();
        hold.advance(3, 3);
        for _ in 0..SUBSTEP_HOLD_STEPS - 1 {
            hold.advance(1, hold.count_for(1));
        }
        hold.advance(3, hold.count_for(3));
        assert_eq!(hold.steps_left, SUBSTEP_HOLD_STEPS);
        // A higher count replaces a lower held one at once.
        hold.advance(4, hold.count_for(4));
        assert_eq!((hold.count, hold.count_for(1)), (4, 4));
    }
}
