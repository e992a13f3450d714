//! `cargo xtask bundle ressort-plugin [--release]` writes `target/bundled/Ressort.clap` and
//! `Ressort.vst3` (the bundle names come from `bundler.toml`).

fn main() -> nice_plug_xtask::Result<()> {
    nice_plug_xtask::main()
}
