//! The contact goal's deep presses on any organ mesh (docs/VALIDATION.md §5): spheres pressed
//! horizontally into the hung organ from each side and measured every step (what is measured and
//! what meets the goal: `press.rs`).
//!
//! ```text
//! cargo run --release --example press_check -- [--radii 1,2.5,5,10] [--sides +x,-x,+z,-z]
//!     [--depth 0.03] [--hold 0.5] [--scale 0.03] [--crushed-substeps N] [--self-contact] MESH...
//! ```
//! `MESH`: a mesh file (TetGen `.node`/`.ele` base, gmsh `.msh`, legacy `.vtk`) or the name of
//! one in `data/meshes`; `--scale` its unit in metres (0.03: the data meshes' organs, 12–21 cm
//! across); `--radii` the sphere radii (mm); `--depth` metres past first contact; `--hold`
//! seconds; `--self-contact` switches the surface self-contact on (`Settings::self_contact`).
//! Exits non-zero when a judged press misses the goal.

mod press;

use press::{hang, press_from, Res, HEADER};
use tissuesim::{Real, Settings};

/// The value after `flag` in `args`, parsed, or `default`.
fn option<T: std::str::FromStr>(args: &[String], flag: &str, default: T) -> Res<T>
where
    T::Err: std::error::Error + 'static,
{
    match args.iter().position(|a| a == flag) {
        Some(i) => Ok(args
            .get(i + 1)
            .ok_or(format!("{flag} needs a value"))?
            .parse()?),
        None => Ok(default),
    }
}

fn main() -> std::process::ExitCode {
    match run() {
        Ok(()) => std::process::ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("press_check: {e}");
            std::process::ExitCode::FAILURE
        }
    }
}

/// Parse the arguments, run every press and report them.
fn run() -> Res<()> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let radii: String = option(&args, "--radii", "1,2.5,5,10".to_string())?;
    let sides: String = option(&args, "--sides", "+x,-x,+z,-z".to_string())?;
    let depth: Real = option(&args, "--depth", 0.03)?;
    let hold: Real = option(&args, "--hold", 0.5)?;
    let scale: Real = option(&args, "--scale", 0.03)?;
    let mut settings = Settings::default();
    settings.crushed_substeps = option(&args, "--crushed-substeps", settings.crushed_substeps)?;
    settings.self_contact = args.iter().any(|a| a == "--self-contact");
    let valued = [
        "--radii",
        "--sides",
        "--depth",
        "--hold",
        "--scale",
        "--crushed-substeps",
    ];
    let meshes: Vec<&String> = (args.iter().enumerate())
        .filter(|&(i, a)| {
            !a.starts_with("--") && (i == 0 || !valued.contains(&args[i - 1].as_str()))
        })
        .map(|(_, a)| a)
        .collect();
    if meshes.is_empty() {
        return Err("give at least one mesh (a file or a name in data/meshes)".into());
    }
    let radii: Vec<Real> = (radii.split(','))
        .map(|r| r.trim().parse::<Real>().map(|mm| mm * 1e-3))
        .collect::<Result<_, _>>()?;
    let (mut judged, mut missed) = (0, Vec::new());
    println!("{HEADER}");
    for name in meshes {
        let organ = hang(name, scale, &settings)?;
        for side in sides.split(',').map(str::trim) {
            for &radius in &radii {
                let shape = (depth, hold);
                let Some(p) = press_from(&organ, &settings, radius, side, shape)? else {
                    println!(
                        "{name} | {} | {side} | the press line misses the organ",
                        radius * 1e3
                    );
                    continue;
                };
                println!("{}", p.row(name, radius, side));
                if p.touched() {
                    judged += 1;
                    if !p.meets(radius) {
                        missed.push(format!("{name} {} mm {side}", radius * 1e3));
                    }
                }
            }
        }
    }
    println!(
        "{} of {judged} judged presses meet the goal",
        judged - missed.len()
    );
    if !missed.is_empty() {
        return Err(format!("missed the goal: {}", missed.join(", ")).into());
    }
    Ok(())
}
