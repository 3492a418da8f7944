//! `clayc`: the command-line edge of Clay. Each subcommand lives in its own module; this file
//! only parses arguments and maps results to exit codes (0 ok, 1 the input has errors, 2 usage
//! or I/O errors). Output goes through [`out`], so a closed pipe never panics.

use std::process::ExitCode;

use clap::{Parser, Subcommand};

// First: its `errln!` / `err!` macros are used by the modules below.
#[macro_use]
mod out;

mod author;
mod bench;
mod check;
mod export;
mod fmt;
mod from_session;
mod lsp;
mod params;
mod render;
mod run;

#[derive(Parser)]
#[command(
    name = "clayc",
    version,
    about = "Check, build, run, render, format and author Clay grammars, and serve them to editors"
)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// Check grammars and print diagnostics.
    Check(check::CheckArgs),
    /// Compile a grammar to JSON.
    Build(check::BuildArgs),
    /// Replay a scripted sculpting session headlessly.
    Run(run::RunArgs),
    /// Benchmark the solver on a synthetic assembly.
    Bench(bench::BenchArgs),
    /// Render an assembly to PNG (or SVG).
    Render(render::RenderArgs),
    /// Export the assembly as 3D meshes (glTF, OBJ or USD).
    Export(export::ExportArgs),
    /// Render every piece and rest state of a grammar side by side.
    Sheet(render::SheetArgs),
    /// Print grammars in the canonical style (or --write / --check them).
    Fmt(fmt::FmtArgs),
    /// Turn an SVG drawing into a grammar.
    Author(author::AuthorArgs),
    /// Run the language server for editors (Language Server Protocol over stdio).
    Lsp(lsp::LspArgs),
}

fn main() -> ExitCode {
    let cli = match Cli::try_parse() {
        Ok(cli) => cli,
        Err(e) => {
            let _ = e.print();
            // clap's own exit code is 2 for usage errors and 0 for --help / --version.
            return ExitCode::from(e.exit_code().clamp(0, 255) as u8);
        }
    };
    let code = match cli.command {
        Command::Check(args) => check::check(args),
        Command::Build(args) => check::build(args),
        Command::Run(args) => run::run(args),
        Command::Bench(args) => bench::bench(args),
        Command::Render(args) => render::render(args),
        Command::Sheet(args) => render::sheet(args),
        Command::Export(args) => export::export(args),
        Command::Fmt(args) => fmt::fmt(args),
        Command::Author(args) => author::author_cmd(args),
        Command::Lsp(args) => lsp::lsp(args),
    };
    ExitCode::from(code)
}
