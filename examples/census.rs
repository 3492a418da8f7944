//! A census of the paper's claims over generated assemblies (issue 46): runs one property of
//! `tests/paper_claims_assemblies.rs` over N cases drawn from a seed and counts the failures
//! instead of stopping at the first (the suite shrinks and stops; this is for the 10^4 runs
//! and for finding the classes that fail). Each failing case prints its index and the first
//! line of its verdict; `--show K` prints case K's whole verdict (grammar and script).
//!
//! ```text
//! cargo run --release --example census -- morph 1000 [--seed 4242] [--show K]
//! ```
//! Properties: morph, speed, round, pulled, relax, states, small, determinism, far.

#[path = "../tests/generated/mod.rs"]
mod generated;

use std::io::Write as _;
use std::process::ExitCode;
use std::sync::atomic::{AtomicUsize, Ordering};

use generated::assembly::{self, Morph, Recipe, claims};
use generated::strategy::round;
use glam::DVec2;

/// splitmix64: a case's numbers from its seed and index, the same on every machine.
struct Draw(u64);

impl Draw {
    fn next(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9e37_79b9_7f4a_7c15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
        z ^ (z >> 31)
    }

    fn unit(&mut self) -> f64 {
        (self.next() >> 11) as f64 / (1u64 << 53) as f64
    }

    fn between(&mut self, lo: f64, hi: f64) -> f64 {
        lo + (hi - lo) * self.unit()
    }

    /// As `strategy::frames`: a jump, a few frames, tens, or hundreds.
    fn frames(&mut self) -> u64 {
        match self.next() % 5 {
            0 => 0,
            1 => 1 + self.next() % 7,
            2 | 3 => 8 + self.next() % 112,
            _ => 120 + self.next() % 361,
        }
    }
}

fn morph(draw: &mut Draw) -> Morph {
    let picks = (0..64).map(|_| draw.next() as u16).collect();
    let sizes = (0..32).map(|_| draw.unit()).collect();
    assembly::build(&Recipe { picks, sizes })
}

/// Case `k` of `property` from `seed`.
fn case(property: &str, seed: u64, k: u64) -> Result<(), String> {
    let mut draw = Draw(seed ^ k.wrapping_mul(0xa076_1d64_78bd_642f));
    let m = morph(&mut draw);
    match property {
        "morph" => claims::morph_to_rest(&m, draw.frames()),
        "speed" => claims::speed(&m),
        "round" => claims::round_trip(&m, draw.frames(), draw.frames()),
        "pulled" => {
            let degrees = round(draw.between(-180.0, 180.0));
            let elements = round(draw.between(0.5, 3.5));
            let by = DVec2::from_angle(degrees.to_radians()) * elements * m.graph.shortest();
            let by = DVec2::new(assembly::round9(by.x), assembly::round9(by.y));
            claims::pulled_and_back(&m, by, draw.frames(), draw.frames())
        }
        "relax" => claims::relaxation(&m, draw.frames()),
        "determinism" => claims::deterministic(&m, draw.frames()),
        "far" => claims::far_pieces_change_nothing(&m, draw.frames()),
        "states" => {
            let frames = 8 + draw.next() % 233;
            let push = DVec2::new(
                round(draw.between(-1.0, 1.0)),
                round(draw.between(-1.0, 1.0)),
            );
            let turn = round(draw.between(-60.0, 60.0));
            claims::states_follow_the_shape(&m, frames, push, turn)
        }
        "small" => claims::small_moves_switch_nothing(
            &m,
            // below 0.999, so that rounded it stays below 1 (`sec4_3_small_moves_switch_nothing`)
            round(0.999 * draw.unit()),
            round(draw.between(-180.0, 180.0)),
        ),
        other => Err(format!("no property `{other}`")),
    }
}

fn main() -> ExitCode {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let flag = |name: &str| {
        let at = args.iter().position(|a| a == name)?;
        args.get(at + 1)?.parse::<u64>().ok()
    };
    let (Some(property), Some(cases)) = (
        args.first().cloned(),
        args.get(1).and_then(|n| n.parse::<u64>().ok()),
    ) else {
        eprintln!("usage: census PROPERTY CASES [--seed S] [--show K]");
        return ExitCode::from(2);
    };
    let seed = flag("--seed").unwrap_or(4242);
    if let Some(k) = flag("--show") {
        return match case(&property, seed, k) {
            Ok(()) => {
                println!("case {k}: holds");
                ExitCode::SUCCESS
            }
            Err(why) => {
                let _ = writeln!(std::io::stdout(), "case {k}: {why}");
                ExitCode::FAILURE
            }
        };
    }
    let next = AtomicUsize::new(0);
    let failed = AtomicUsize::new(0);
    let threads = std::thread::available_parallelism().map_or(1, |n| n.get());
    std::thread::scope(|s| {
        for _ in 0..threads {
            s.spawn(|| {
                loop {
                    let k = next.fetch_add(1, Ordering::Relaxed) as u64;
                    if k >= cases {
                        break;
                    }
                    if let Err(why) = case(&property, seed, k) {
                        failed.fetch_add(1, Ordering::Relaxed);
                        let first = why.lines().next().unwrap_or("");
                        // a closed pipe (`| head`) ends the report, not the run in a panic
                        let _ = writeln!(std::io::stdout(), "case {k}: {first}");
                    }
                }
            });
        }
    });
    let failed = failed.into_inner();
    println!("{property}: {failed} of {cases} failed (seed {seed})");
    if failed == 0 {
        ExitCode::SUCCESS
    } else {
        ExitCode::FAILURE
    }
}
