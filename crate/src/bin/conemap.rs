//! The conemap command-line tool (OWNER: mesh-core helper for `info`).
fn main() {
    eprintln!("conemap: not implemented yet");
    std::process::exit(2);
}
