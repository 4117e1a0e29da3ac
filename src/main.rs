//! The `sagcal` command line: a thin layer over the library.

mod cli;

fn main() {
    // Rust ignores SIGPIPE, so printing into a closed pipe (`sagcal ... | head`)
    // would panic; a command-line tool should end quietly like any other.
    #[cfg(unix)]
    // SAFETY: called first thing in main, before any thread exists; SIG_DFL is a valid action.
    unsafe {
        libc::signal(libc::SIGPIPE, libc::SIG_DFL);
    }
    let code = cli::run();
    // The work count a test bounds a command's running time by (`sagcal::steps`).
    if std::env::var_os("SAGCAL_REPORT_STEPS").is_some() {
        eprintln!("sagcal steps: {}", sagcal::steps::total());
    }
    std::process::exit(code);
}
