//! The deep presses of `examples/press_check` that the suite keeps: presses on organs the
//! contact was not chosen on, measured every step against the deformed surface
//! (`examples/press_check/press.rs`: the probe's centre, the surface's depth in the probe, the
//! pulling steps, the tissue's speed and the rolled-back steps).

#[path = "../examples/press_check/press.rs"]
mod press;

use press::{hang, press_from, HEADER};
use tissuesim::Settings;

/// liver_1k6, a 2.5 mm sphere along +z (its press line enters a cleft), pressed 3 cm and held
/// 0.5 s. The narrow-tool rule switches its steps between one and two substeps; before the
/// substep hold (`SUBSTEP_HOLD_STEPS`) a part of the organ 10 cm from the probe rang up until
/// the step diverged at 0.60 s, and then on 1,178 of its 1,780 steps (particles at 65 m/s).
/// Measured with the hold: the goal met, the fastest particle at 0.36 m/s, nothing rolled back.
#[test]
fn a_press_that_switches_substep_counts_meets_the_goal_without_diverging() {
    let settings = Settings::default();
    let organ = hang("liver_1k6", 0.03, &settings).unwrap();
    let radius = 0.0025;
    let p = press_from(&organ, &settings, radius, "+z", (0.03, 0.5))
        .unwrap()
        .expect("the press line meets the organ");
    let row = format!("{HEADER}\n{}", p.row("liver_1k6", radius, "+z"));
    assert!(p.touched() && p.meets(radius), "{row}");
    assert!(p.fastest < 1.0, "the tissue rings: {row}");
}
