//! `clayc run` (placeholder until the solver lands).
#[derive(clap::Args)]
pub struct RunArgs {
    pub file: std::path::PathBuf,
}
pub fn run(_: RunArgs) -> u8 {
    eprintln!("clayc run: not built yet");
    2
}
