//! The CLI's own surface: `--version`, shell completions, figures written
//! as PNG for a `.png` name, and the kernel switch checked before any work.

use std::path::Path;

#[path = "common/cli.rs"]
mod cli;
use cli::{robot, sagcal};

#[test]
fn version_prints_the_crate_version() {
    let out = sagcal(Path::new("."), &["--version"]);
    assert!(out.status.success());
    assert_eq!(
        String::from_utf8_lossy(&out.stdout).trim(),
        format!("sagcal {}", env!("CARGO_PKG_VERSION"))
    );
}

#[test]
fn completions_for_bash_zsh_and_fish_name_every_command() {
    for (shell, marker) in [
        ("bash", "_sagcal()"),
        ("zsh", "#compdef sagcal"),
        ("fish", "complete -c sagcal"),
    ] {
        let out = sagcal(Path::new("."), &["completions", shell]);
        assert!(
            out.status.success(),
            "{shell}: {}",
            String::from_utf8_lossy(&out.stderr)
        );
        let script = String::from_utf8(out.stdout).unwrap();
        assert!(script.contains(marker), "{shell}: no `{marker}`");
        for word in [
            "calibrate",
            "diagnose",
            "localize",
            "simulate",
            "verify",
            "completions",
            "plot-format",
        ] {
            assert!(script.contains(word), "{shell} completions lack `{word}`");
        }
    }
    let out = sagcal(Path::new("."), &["completions", "tcsh"]);
    assert_eq!(out.status.code(), Some(2), "an unknown shell is a usage error");
    assert!(String::from_utf8_lossy(&out.stderr).contains("bash"));
}

#[test]
fn calibrate_plot_with_a_png_name_writes_a_png() {
    let dir = tempfile::tempdir().unwrap();
    let robot = robot("small");
    let out = sagcal(
        dir.path(),
        &[
            "simulate", "--robot", &robot, "--poses", "12", "--seed", "5", "--out", "m.csv",
        ],
    );
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    for name in ["a.png", "a.svg"] {
        let out = sagcal(
            dir.path(),
            &["calibrate", "--robot", &robot, "--data", "m.csv", "--plot", name],
        );
        assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    }
    let png = std::fs::read(dir.path().join("a.png")).unwrap();
    assert_eq!(&png[..8], b"\x89PNG\r\n\x1a\n");
    let svg = std::fs::read_to_string(dir.path().join("a.svg")).unwrap();
    assert!(svg.trim_end().ends_with("</svg>"));
    // The PNG is the SVG at twice its pixels.
    let width = |s: &str| -> u32 {
        let at = s.find("<svg").unwrap();
        let w = &s[at..][s[at..].find(" width=\"").unwrap() + 8..];
        w[..w.find('"').unwrap()].parse().unwrap()
    };
    assert_eq!(
        u32::from_be_bytes([png[16], png[17], png[18], png[19]]),
        2 * width(&svg)
    );
}

#[test]
fn a_mistyped_kernel_switch_is_refused_before_any_work() {
    let dir = std::env::temp_dir().join(format!("sagcal-simd-switch-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let out = std::process::Command::new(env!("CARGO_BIN_EXE_sagcal"))
        .args(["demo", "--poses", "9"])
        .current_dir(&dir)
        .env("SAGCAL_SIMD", "fast")
        .output()
        .unwrap();
    let written = std::fs::read_dir(&dir).unwrap().count();
    std::fs::remove_dir_all(&dir).unwrap();
    assert_eq!(out.status.code(), Some(2));
    assert_eq!(
        String::from_utf8_lossy(&out.stderr).trim(),
        "error: SAGCAL_SIMD=\"fast\": expected portable, avx2 or auto"
    );
    assert_eq!(written, 0, "nothing is written");
}
