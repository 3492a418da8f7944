//! `clayc fmt FILE...`: prints grammar files in the canonical style (clay_dsl::format), or with
//! `--write` rewrites them in place (temp file, then rename), or with `--check` lists the files
//! that would change. Exit codes: 0 fine, 1 a file would change or does not parse, 2 I/O.

use std::path::{Path, PathBuf};

use crate::out;

#[derive(clap::Args)]
pub struct FmtArgs {
    /// Grammar files to format (`-` reads standard input).
    #[arg(required = true)]
    pub files: Vec<PathBuf>,
    /// Rewrite the files in place instead of printing them.
    #[arg(long, conflicts_with = "check")]
    pub write: bool,
    /// Print nothing but the names of files that are not formatted; exit 1 if there are any.
    #[arg(long)]
    pub check: bool,
}

fn read(path: &Path) -> std::io::Result<Vec<u8>> {
    if path.as_os_str() == "-" {
        clay_dsl::read_bounded(std::io::stdin(), clay_dsl::MAX_SOURCE_BYTES)
    } else {
        clay_dsl::read_input(path, clay_dsl::MAX_SOURCE_BYTES)
    }
}

pub fn fmt(args: FmtArgs) -> u8 {
    let mut worst = 0u8;
    for file in &args.files {
        let path = file.display().to_string();
        if args.write && file.as_os_str() == "-" {
            errln!("error: --write needs files, not standard input");
            worst = 2;
            continue;
        }
        let bytes = match read(file) {
            Ok(b) => b,
            Err(e) => {
                errln!("error: cannot read `{path}`: {e}");
                worst = 2;
                continue;
            }
        };
        let source = String::from_utf8_lossy(&bytes);
        let formatted = clay_dsl::decode_utf8(&bytes).and_then(clay_dsl::format);
        let formatted = match formatted {
            Ok(f) => f,
            Err(diags) => {
                err!("{}", clay_dsl::render(&diags, &source, &path, false));
                errln!("error: `{path}` was not formatted: it does not parse");
                worst = worst.max(1);
                continue;
            }
        };
        let changed = formatted.as_bytes() != bytes.as_slice();
        if args.check {
            if changed {
                worst = worst.max(1);
                if let Err(stop) = out::stdout_line(&path) {
                    return stop.exit(worst);
                }
            }
        } else if args.write {
            if changed && let Err(e) = clay::write_atomic(file, formatted.as_bytes()) {
                errln!("error: cannot write `{path}`: {e}");
                worst = 2;
            }
        } else if let Err(stop) = out::stdout(formatted.as_bytes()) {
            return stop.exit(worst);
        }
    }
    worst
}
