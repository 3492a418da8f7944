//! `clayc check` and `clayc build` (placeholder until the compiler lands).
#[derive(clap::Args)]
pub struct CheckArgs {
    pub files: Vec<std::path::PathBuf>,
}
#[derive(clap::Args)]
pub struct BuildArgs {
    pub file: std::path::PathBuf,
}
pub fn check(_: CheckArgs) -> u8 {
    eprintln!("clayc check: not built yet");
    2
}
pub fn build(_: BuildArgs) -> u8 {
    eprintln!("clayc build: not built yet");
    2
}
