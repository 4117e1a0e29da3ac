//! `sagcal init`: a new, commented robot file from a few numbers; its flags
//! ([`InitArgs`]) and the run. The library does the work
//! (`sagcal::io::robot_init`); this file turns flags into a `RobotInit`.

use std::path::PathBuf;

use sagcal::error::FrontEnd;
use sagcal::io::robot_init::{robot_file_text, write_robot_file, Heaviness, RobotInit};
use sagcal::model::robot::Workspace;

#[derive(Debug, clap::Args)]
pub(super) struct InitArgs {
    /// Start from a built-in robot (`large`, `small`): every value not given is the template's.
    #[arg(long, value_name = "large|small")]
    from_template: Option<String>,
    /// A cable's anchor, the point where it leaves its pulley: `x,y,z`, world frame (z up), metres.
    /// Once per cable, in cable order (`--anchor=-6,-2,8 --anchor 6,-2,8 ...`).
    #[arg(long, value_name = "X,Y,Z", value_parser = parse_point, allow_hyphen_values = true)]
    anchor: Vec<[f64; 3]>,
    /// A cable's attachment point on the platform: `x,y,z`, platform frame, metres. Once per cable, in cable order.
    #[arg(long, value_name = "X,Y,Z", value_parser = parse_point, allow_hyphen_values = true)]
    attachment: Vec<[f64; 3]>,
    /// The platform's mass with its payload, kilograms (or --platform-weight-n).
    #[arg(long, conflicts_with = "platform_weight_n")]
    platform_mass_kg: Option<f64>,
    /// The platform's weight m g, newtons.
    #[arg(long)]
    platform_weight_n: Option<f64>,
    /// The cables' mass per metre, kilograms (0.0724 for 72.4 g/m; or --cable-weight-n-per-m).
    #[arg(long, conflicts_with = "cable_weight_n_per_m")]
    cable_mass_per_m_kg: Option<f64>,
    /// The cables' weight per metre, newtons per metre.
    #[arg(long)]
    cable_weight_n_per_m: Option<f64>,
    /// The cables' axial stiffness EA (Young's modulus x cross-section), newtons; omitted: inextensible.
    #[arg(long)]
    axial_stiffness_n: Option<f64>,
    /// The platform's centre of mass: `x,y,z`, platform frame, metres (default 0,0,0).
    #[arg(long, value_name = "X,Y,Z", value_parser = parse_point, allow_hyphen_values = true)]
    com_offset_m: Option<[f64; 3]>,
    /// The cable with the load cell, 1..4 in the order of the anchors (default 1).
    #[arg(long)]
    reference_cable: Option<usize>,
    /// The box calibration poses are drawn from: `x0,x1,y0,y1,z0,z1`, world frame, metres.
    #[arg(long, value_name = "X0,X1,Y0,Y1,Z0,Z1", value_parser = parse_box, allow_hyphen_values = true)]
    workspace: Option<Workspace>,
    /// The robot's name (default: the --out file's name).
    #[arg(long)]
    name: Option<String>,
    /// Write the robot file here (atomically); without it the file is printed.
    #[arg(long)]
    out: Option<PathBuf>,
    /// Replace --out if it exists.
    #[arg(long, requires = "out")]
    force: bool,
}

/// Write (or print) the robot file the flags describe.
pub fn run(args: &InitArgs) -> sagcal::Result<()> {
    let heaviness =
        |mass: Option<f64>, weight: Option<f64>| mass.map(Heaviness::MassKg).or(weight.map(Heaviness::WeightN));
    let name = args.name.clone().or_else(|| {
        let stem = args.out.as_ref()?.file_stem()?;
        Some(stem.to_string_lossy().into_owned())
    });
    let init = RobotInit {
        template: args.from_template.clone(),
        name,
        anchors_m: args.anchor.clone(),
        attachments_m: args.attachment.clone(),
        platform: heaviness(args.platform_mass_kg, args.platform_weight_n),
        cable: heaviness(args.cable_mass_per_m_kg, args.cable_weight_n_per_m),
        axial_stiffness_n: args.axial_stiffness_n,
        com_offset_m: args.com_offset_m,
        reference_cable: args.reference_cable,
        workspace: args.workspace,
    };
    let Some(out) = &args.out else {
        print!("{}", robot_file_text(&init, FrontEnd::Cli)?.text);
        return Ok(());
    };
    let new = write_robot_file(&init, FrontEnd::Cli, out, args.force)?;
    let robot = &new.robot;
    println!(
        "wrote {}: robot `{}`, {} cables, reference cable {}, platform {} N, cables {} N/m{}",
        out.display(),
        robot.name,
        robot.anchors_m.len(),
        robot.reference_cable + 1,
        robot.platform_weight_n,
        robot.cable_weight_n_per_m,
        robot
            .effects
            .axial_stiffness_n
            .map(|ea| format!(", EA {ea} N"))
            .unwrap_or_default()
    );
    println!(
        "next: sagcal check --robot {} --data YOUR_DATA.csv (what sagcal reads from your data, before any fit)",
        out.display()
    );
    Ok(())
}

/// `N` comma-separated finite numbers.
fn numbers<const N: usize>(text: &str) -> Result<[f64; N], String> {
    let parts: Vec<&str> = text.split(',').map(str::trim).collect();
    if parts.len() != N {
        return Err(format!("expected {N} comma-separated numbers, got {}", parts.len()));
    }
    let mut values = [0.0; N];
    for (value, part) in values.iter_mut().zip(&parts) {
        *value = part
            .parse::<f64>()
            .ok()
            .filter(|v| v.is_finite())
            .ok_or_else(|| format!("`{part}` is not a finite number"))?;
    }
    Ok(values)
}

/// `x,y,z`.
fn parse_point(text: &str) -> Result<[f64; 3], String> {
    numbers::<3>(text)
}

/// `x0,x1,y0,y1,z0,z1` (the form `plan --workspace` takes).
fn parse_box(text: &str) -> Result<Workspace, String> {
    let [x0, x1, y0, y1, z0, z1] = numbers::<6>(text)?;
    Ok(Workspace {
        min_m: [x0, y0, z0],
        max_m: [x1, y1, z1],
    })
}
