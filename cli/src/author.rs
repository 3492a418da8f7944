//! `clayc author DRAWING.svg -o OUT.clay [--cut x,y]... [--stretch] [--variant P=F]...
//! [--merge A.s:B.t[:J.u]]... [--state P:NAME:x,y;x,y;...]... [--tolerance T] [--scale S]`:
//! turns an SVG drawing into a grammar through `clay::authoring::compute`, the same
//! steps as the editor's author mode. Exit codes: 0 written, 1 the drawing or a declaration
//! cannot become a grammar, 2 usage or I/O.

use std::path::PathBuf;

use crate::out;
use clay::{
    authoring::MIN_TOLERANCE, authoring::MergeChoice, authoring::SiteName, authoring::StateChoice,
    authoring::StretchChoice, authoring::VariantChoice, authoring::Work, authoring::check_authored,
    authoring::compute, authoring::drawing_from_svg, authoring::line_of_id as svg_line_of_id,
};
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
    /// A variant of the stretch piece and its target frequency, e.g. `long_brick=0.25`;
    /// repeatable (the stretch piece itself may be listed too).
    #[arg(long = "variant", value_name = "PIECE=FREQ")]
    pub variants: Vec<String>,
    /// A merge rule `MOVER.SITE:TARGET.SITE`, or with a junction `...:JUNCTION.SITE`.
    #[arg(long = "merge", value_name = "A.s:B.t[:J.u]")]
    pub merges: Vec<String>,
    /// An alternative rest state: `PIECE:NAME:x,y;x,y;...`, one position per vertex of the
    /// piece in the piece's own coordinates and vertex order (`v0`, `v1`, ...).
    #[arg(long = "state", value_name = "PIECE:NAME:XY;...")]
    pub states: Vec<String>,
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

fn parse_site(s: &str, flag: &str) -> Result<SiteName, String> {
    match s.split_once('.') {
        Some((piece, site)) if !piece.is_empty() && !site.is_empty() => Ok(SiteName {
            piece: piece.to_string(),
            site: site.to_string(),
        }),
        _ => Err(format!("{flag} {s}: expected PIECE.SITE")),
    }
}

fn parse_merge(s: &str) -> Result<MergeChoice, String> {
    let parts: Vec<&str> = s.split(':').collect();
    if !(2..=3).contains(&parts.len()) {
        return Err(format!(
            "--merge {s}: expected MOVER.SITE:TARGET.SITE[:JUNCTION.SITE]"
        ));
    }
    Ok(MergeChoice {
        mover: parse_site(parts[0], "--merge")?,
        target: parse_site(parts[1], "--merge")?,
        junction: parts.get(2).map(|j| parse_site(j, "--merge")).transpose()?,
    })
}

fn parse_variant(s: &str) -> Result<VariantChoice, String> {
    let (piece, f) = s
        .split_once('=')
        .ok_or_else(|| format!("--variant {s}: expected PIECE=FREQ"))?;
    match f.trim().parse::<f64>() {
        Ok(frequency) if frequency.is_finite() && frequency > 0.0 => Ok(VariantChoice {
            piece: piece.trim().to_string(),
            frequency,
        }),
        _ => Err(format!(
            "--variant {s}: the frequency must be a positive number"
        )),
    }
}

fn parse_state(s: &str) -> Result<StateChoice, String> {
    let mut parts = s.splitn(3, ':');
    let (Some(piece), Some(name), Some(points)) = (parts.next(), parts.next(), parts.next()) else {
        return Err(format!("--state {s}: expected PIECE:NAME:x,y;x,y;..."));
    };
    let positions = points
        .split(';')
        .filter(|p| !p.trim().is_empty())
        .map(|p| {
            parse_point(p).map_err(|e| format!("--state {s}: {}", e.trim_start_matches("--cut ")))
        })
        .collect::<Result<Vec<_>, _>>()?;
    Ok(StateChoice {
        piece: piece.to_string(),
        name: name.to_string(),
        positions,
    })
}

/// The work the arguments describe (the drawing filled in by the caller).
fn work_from(args: &AuthorArgs) -> Result<Work, String> {
    let cuts = args
        .cuts
        .iter()
        .map(|c| parse_point(c))
        .collect::<Result<Vec<_>, _>>()?;
    if !(args.tolerance.is_finite() && args.tolerance >= MIN_TOLERANCE) {
        return Err(format!(
            "--tolerance must be a number of metres from {MIN_TOLERANCE} up (the grammar is written to the micrometre)"
        ));
    }
    if !args.variants.is_empty() && !args.stretch {
        return Err("--variant needs --stretch: variants belong to the stretch rule".into());
    }
    Ok(Work {
        cuts,
        stretch: args.stretch.then_some(StretchChoice::Auto),
        merges: args
            .merges
            .iter()
            .map(|m| parse_merge(m))
            .collect::<Result<_, _>>()?,
        variants: args
            .variants
            .iter()
            .map(|v| parse_variant(v))
            .collect::<Result<_, _>>()?,
        states: args
            .states
            .iter()
            .map(|s| parse_state(s))
            .collect::<Result<_, _>>()?,
        tolerance: args.tolerance,
        ..Work::default()
    })
}

/// `error: FILE[:LINE]: message`, the line being that of the SVG element a message names
/// (`path `ID``), when the drawing has one such id.
fn report(path: &str, svg: &str, message: &str) {
    let line = message
        .split_once("path `")
        .and_then(|(_, rest)| rest.split_once('`'))
        .and_then(|(id, _)| svg_line_of_id(svg, id));
    match line {
        Some(line) => errln!("error: {path}:{line}: {message}"),
        None => errln!("error: {path}: {message}"),
    }
}

pub fn author_cmd(args: AuthorArgs) -> u8 {
    let mut work = match work_from(&args) {
        Ok(w) => w,
        Err(e) => {
            errln!("error: {e}");
            return 2;
        }
    };
    let path = args.drawing.display().to_string();
    let svg = match clay_dsl::read_input_string(&args.drawing, clay_dsl::MAX_SOURCE_BYTES) {
        Ok(t) => t,
        Err(e) => {
            errln!("error: cannot read `{path}`: {e}");
            return 2;
        }
    };
    let drawing = match drawing_from_svg(&svg, args.scale) {
        Ok(d) => d,
        Err(e) => {
            report(&path, &svg, &e.to_string());
            return 1;
        }
    };
    work.drawing = drawing;
    let computed = match compute(&work) {
        Ok(c) => c,
        Err(e) => {
            report(&path, &svg, &e);
            return 1;
        }
    };
    // A declaration the drawing cannot take is an error here (the editor keeps it as a note
    // while the author is still drawing).
    let refused: Vec<&String> = computed
        .design
        .notes
        .iter()
        .filter(|n| n.contains("no longer applies"))
        .collect();
    if !refused.is_empty() {
        for n in refused {
            errln!(
                "error: {path}: {}",
                n.replace("no longer applies", "does not apply")
            );
        }
        return 1;
    }
    for note in &computed.design.notes {
        errln!("note: {note}");
    }
    let mut text = format!(
        "// Authored by `clayc author` from {} (1 SVG unit = {} m, y up).\n",
        path, args.scale
    );
    text += &computed.text;
    // The last line of defence: never write a grammar that fails `clayc check`.
    let out_name = args.output.display().to_string();
    if let Err(e) = check_authored(&text, &out_name) {
        errln!("error: {path}: {e}");
        return 1;
    }
    let code = out::write_output(&args.output, text.as_bytes());
    if code != 0 {
        return code;
    }
    let d = &computed.design;
    errln!(
        "authored {} piece(s), {} instance(s), {} dock(s)",
        d.pieces.len(),
        d.instances.len(),
        d.docks.len()
    );
    0
}
