//! Golden harness: every case in `golden/cases.toml` is its own named test
//! (`golden::<kernel>::<case>`), so `cargo test fbm` and nextest filter and
//! shard them; after the run the report is written. It is the harness any
//! crate gets with `vista::harness::main()`.

fn main() {
    vista::harness::main()
}
