//! The `sagcal` command line.
fn main() {
    std::process::exit(sagcal_cli_main());
}

fn sagcal_cli_main() -> i32 {
    0
}
