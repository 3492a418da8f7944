//! `clayc author DRAWING.svg -o OUT.clay [--cut x,y]... [--stretch] [--tolerance T] [--scale S]`:
//! turns an SVG drawing into a grammar through `clay::authoring`. Exit codes: 0 written, 1 the
//! drawing cannot become a grammar, 2 usage or I/O.

use std::path::PathBuf;

use crate::out;
use clay::authoring::{AuthorOptions, StretchChoice, author, svg::drawing_from_svg};
use glam::DVec2;

#[derive(clap::Args)]
pub struct AuthorArgs {
    /// The SVG drawing.
    pub drawing: PathBuf,
    /// Where to write the grammar (`-` for standard output).
    #[arg(short = 'o', long = "output")]
    pub output: PathBuf,
    /// Cut the drawing at this point, in metres with y up (after --scale); repeatable.
    #[arg(long = "cut", value_name = "X,Y")]
    pub cuts: Vec<String>,
    /// Make the most repeated piece stretchable between its two opposite docked sites.
    #[arg(long)]
    pub stretch: bool,
    /// Snap and congruence tolerance in metres.
    #[arg(long, default_value_t = 0.001)]
    pub tolerance: f64,
    /// Metres per SVG unit (0.01: one unit is one centimetre).
    #[arg(long, default_value_t = 0.01)]
    pub scale: f64,
}

fn parse_point(s: &str) -> Result<DVec2, String> {
    let (x, y) = s
        .split_once(',')
        .ok_or_else(|| format!("--cut {s}: expected X,Y"))?;
    let num = |t: &str| t.trim().parse::<f64>().ok().filter(|v| v.is_finite());
    match (num(x), num(y)) {
        (Some(x), Some(y)) => Ok(DVec2::new(x, y)),
        _ => Err(format!("--cut {s}: X and Y must be finite numbers")),
    }
}

pub fn author_cmd(args: AuthorArgs) -> u8 {
    let mut cuts = Vec::new();
    for c in &args.cuts {
        match parse_point(c) {
            Ok(p) => cuts.push(p),
            Err(e) => {
                errln!("error: {e}");
                return 2;
            }
        }
    }
    if !(args.tolerance.is_finite() && args.tolerance > 0.0) {
        errln!("error: --tolerance must be a positive number of metres");
        return 2;
    }
    let path = args.drawing.display().to_string();
    let text = match std::fs::read_to_string(&args.drawing) {
        Ok(t) => t,
        Err(e) => {
            errln!("error: cannot read `{path}`: {e}");
            return 2;
        }
    };
    let drawing = match drawing_from_svg(&text, args.scale) {
        Ok(d) => d,
        Err(e) => {
            errln!("error: {path}: {e}");
            return 1;
        }
    };
    let options = AuthorOptions {
        snap: args.tolerance,
        congruence: args.tolerance,
        cuts,
        stretch: args.stretch.then_some(StretchChoice::Auto),
        header: Some(format!(
            "Authored by `clayc author` from {} (1 SVG unit = {} m, y up).",
            path, args.scale
        )),
    };
    let authored = match author(&drawing, &options) {
        Ok(a) => a,
        Err(e) => {
            errln!("error: {path}: {e}");
            return 1;
        }
    };
    for note in &authored.design.notes {
        errln!("note: {note}");
    }
    let code = out::write_output(&args.output, authored.text.as_bytes());
    if code != 0 {
        return code;
    }
    let d = &authored.design;
    errln!(
        "authored {} piece(s), {} instance(s), {} dock(s)",
        d.pieces.len(),
        d.instances.len(),
        d.docks.len()
    );
    0
}
