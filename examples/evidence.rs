//! Evidence for docs/history/VALIDATION_HISTORY.md: accuracy against FEM, the paper's experiments and the probe
//! force trace. Each subcommand runs scenes and writes CSV files that `validation/accuracy.py`
//! and `validation/paper_experiments.py` turn into tables and plots (see docs/VALIDATION.md).
//!
//! ```text
//! cargo run --release --example evidence -- static --scene liver030 [--no-volume] [--neighbours N]
//!                                            [--hourglass C] [--iterations K] [--dt S] [--out CSV]
//! cargo run --release --example evidence -- accuracy --out DIR      # every static run of docs/VALIDATION.md
//! cargo run --release --example evidence -- volume --out CSV         # paper Fig. 6
//! cargo run --release --example evidence -- runtime --out CSV        # paper Fig. 7
//! cargo run --release --example evidence -- large --out DIR          # paper Fig. 9 (+ VTU into DIR/vtu)
//! cargo run --release --example evidence -- press --out CSV  # probe force trace
//! ```
//! Meshes are read from the repository's `data/meshes`, or from `$TISSUESIM_MESHES` when set.

#[path = "evidence/accuracy.rs"]
mod accuracy;
#[path = "evidence/common.rs"]
mod common;
#[path = "evidence/experiments.rs"]
mod experiments;
#[path = "evidence/press.rs"]
mod press;

use std::collections::HashMap;

/// Parsed `--key value` options and `--flag` switches.
pub struct Args {
    values: HashMap<String, String>,
}

impl Args {
    fn parse(raw: &[String]) -> Result<Args, String> {
        let mut values = HashMap::new();
        let mut i = 0;
        while i < raw.len() {
            let key = raw[i]
                .strip_prefix("--")
                .ok_or_else(|| format!("expected --option, got {}", raw[i]))?;
            if i + 1 < raw.len() && !raw[i + 1].starts_with("--") {
                values.insert(key.to_string(), raw[i + 1].clone());
                i += 2;
            } else {
                values.insert(key.to_string(), String::new());
                i += 1;
            }
        }
        Ok(Args { values })
    }
    /// The value of `--key`, or `default`.
    pub fn get<T: std::str::FromStr>(&self, key: &str, default: T) -> Result<T, String> {
        match self.values.get(key) {
            Some(v) => v
                .parse()
                .map_err(|_| format!("--{key}: cannot parse {v:?}")),
            None => Ok(default),
        }
    }
    /// The string value of `--key`, or `default`.
    pub fn string(&self, key: &str, default: &str) -> String {
        self.values
            .get(key)
            .cloned()
            .unwrap_or_else(|| default.to_string())
    }
    /// True when `--key` was given.
    pub fn flag(&self, key: &str) -> bool {
        self.values.contains_key(key)
    }
}

const USAGE: &str = "usage: evidence (static|accuracy|volume|runtime|large|press) [--options]\n\
see the header of examples/evidence.rs";

fn main() {
    let raw: Vec<String> = std::env::args().skip(1).collect();
    let Some(command) = raw.first() else {
        eprintln!("{USAGE}");
        std::process::exit(2);
    };
    let args = match Args::parse(&raw[1..]) {
        Ok(a) => a,
        Err(e) => {
            eprintln!("{e}\n{USAGE}");
            std::process::exit(2);
        }
    };
    let result = match command.as_str() {
        "static" => accuracy::static_command(&args),
        "accuracy" => accuracy::accuracy_command(&args),
        "volume" => experiments::volume_command(&args),
        "runtime" => experiments::runtime_command(&args),
        "large" => experiments::large_command(&args),
        "press" => press::press_command(&args),
        _ => Err(format!("unknown subcommand {command}\n{USAGE}").into()),
    };
    if let Err(e) = result {
        eprintln!("error: {e}");
        std::process::exit(1);
    }
}
