//! Scratch (temporary): writes a synthetic city as a compiled-grammar JSON for manual checks.
fn main() {
    let n: usize = std::env::args().nth(1).and_then(|a| a.parse().ok()).unwrap_or(10_000);
    let g = clay::synthetic::city(n);
    std::fs::write("/tmp/city.json", serde_json::to_string(&g).unwrap()).unwrap();
    println!("{} parts", g.assembly.parts.len().max(g.parts(&g.assembly).len()));
}
