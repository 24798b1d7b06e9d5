// Every case of golden/cases.toml as a test named golden::<kernel>::<case>.
fn main() {
    vista::harness::main()
}
