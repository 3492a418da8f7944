//! `clayc bench` (placeholder until the solver lands).
#[derive(clap::Args)]
pub struct BenchArgs {}
pub fn bench(_: BenchArgs) -> u8 {
    eprintln!("clayc bench: not built yet");
    2
}
