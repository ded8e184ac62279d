//! What a change of the time step costs (an FMU master varying its communication step): the
//! default organ stepped with `dt` alternating between 1 and 0.9 ms, `World::set_settings`
//! timed before each step (ms, median and largest of 40).
//!
//! ```text
//! cargo run --release --example time_step_change
//! ```

use tissuesim::{mesh, BodyOptions, Settings, World};

fn main() -> Result<(), tissuesim::Error> {
    let mut world = World::new(Settings::default())?;
    world.add_body(&mesh::default_organ(), &BodyOptions::default())?;
    let mut times = Vec::new();
    for k in 0..40 {
        let dt = if k % 2 == 0 { 1.0e-3 } else { 0.9e-3 };
        let settings = Settings {
            dt,
            ..world.settings().clone()
        };
        let start = std::time::Instant::now();
        world.set_settings(settings)?;
        times.push(start.elapsed().as_secs_f64() * 1e3);
        world.step()?;
    }
    times.sort_by(f64::total_cmp);
    println!(
        "set_settings with a new dt: median {:.3} ms, largest {:.3} ms",
        times[times.len() / 2],
        times[times.len() - 1]
    );
    Ok(())
}
