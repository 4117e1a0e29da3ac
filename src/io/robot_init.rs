//! A new robot file from a few numbers (`sagcal init`, `sagcal.init_robot`
//! in Python): the four anchors, the four attachment points, the platform's
//! and the cables' heaviness, optionally the cables' axial stiffness, the
//! centre of mass, the reference cable, a workspace and a name, or a
//! built-in robot to start from ([`RobotInit`]).
//!
//! The text is the format `robots/*.toml` use ([`crate::io::robot_file`]),
//! every key with a comment saying what it means, its frame, unit and sign
//! ([`robot_file_text`]). Before anything is written the robot passes the
//! crate's own checks: the fields one by one, a suspended robot
//! ([`crate::model::geometry::check_robot`]) of plausible magnitudes
//! ([`crate::model::plausibility`]), the checks below, and the text read back
//! gives the same robot, to the last bit. A refusal names the input as the
//! caller spells it ([`InitInput::named`]: `--platform-mass-kg` on the
//! command line, `platform_mass_kg` in Python) with the reason.
//!
//! Checks of this module, for numbers typed by hand:
//!
//! | input | refused when | why |
//! |---|---|---|
//! | anchors | farther apart than [`MAX_ANCHOR_SPREAD_M`] | larger than any robot hung from cables: metres typed as millimetres |
//! | attachments | the platform's diameter is the anchors' footprint width or more | a platform as wide as the space between its anchors cannot move in it |
//! | centre of mass | horizontally beyond the attachment points | a payload whose weight acts outside its cables' points tips off the platform |
//! | axial stiffness | below [`MIN_STIFFNESS_TO_WEIGHT`] times the platform weight | a cable stretching a tenth under the platform's weight is an elastic cord, not a robot's cable |
//!
//! ```
//! use sagcal::error::FrontEnd;
//! use sagcal::io::robot_init::{robot_file_text, Heaviness, RobotInit};
//! let init = RobotInit {
//!     name: Some("lab".into()),
//!     anchors_m: vec![[-6.0, -2.0, 8.0], [6.0, -2.0, 8.0], [6.0, 2.0, 8.0], [-6.0, 2.0, 8.0]],
//!     attachments_m: vec![[-0.2, -0.2, 0.0], [0.2, -0.2, 0.0], [0.2, 0.2, 0.0], [-0.2, 0.2, 0.0]],
//!     platform: Some(Heaviness::MassKg(5.0)),
//!     cable: Some(Heaviness::MassKg(0.01)),
//!     com_offset_m: Some([0.0, 0.0, -0.1]),
//!     ..RobotInit::default()
//! };
//! let new = robot_file_text(&init, FrontEnd::Cli)?;
//! assert!((new.robot.platform_weight_n - 5.0 * 9.81).abs() < 1e-12);
//! assert!(new.text.contains("# Platform weight m_e g"));
//! // Attachment points typed in millimetres: refused, naming the flag.
//! let mm = RobotInit { attachments_m: init.attachments_m.iter().map(|b| b.map(|v| 1e3 * v)).collect(), ..init.clone() };
//! let message = robot_file_text(&mm, FrontEnd::Cli).unwrap_err().to_string();
//! assert!(message.contains("--attachment"), "{message}");
//! # Ok::<(), sagcal::Error>(())
//! ```

use std::path::Path;

use nalgebra::Vector3;

use crate::error::{Error, FrontEnd, Result};
use crate::io::atomic::write_atomically;
use crate::io::robot_file::{CableEntry, RobotFile, WorkspaceEntry};
use crate::io::robot_text::{commented_text, Notes};
use crate::model::geometry::{Footprint, MIN_FOOTPRINT_WIDTH_FRACTION};
use crate::model::robot::{Robot, Workspace, CABLE_COUNT};

pub use crate::model::plausibility::STANDARD_GRAVITY_M_S2;

/// The largest distance between two anchors a new robot may have, metres:
/// over three times the 600 m circle of towers the FAST telescope hangs its
/// feed cabin from, the largest structure moved by cables; anchors farther
/// apart were typed in millimetres (or another unit) instead of metres.
pub const MAX_ANCHOR_SPREAD_M: f64 = 2000.0;

/// A cable's axial stiffness `EA` must be at least this many times the
/// platform's weight: softer, the cable stretches more than a tenth of its
/// length under the weight the platform hangs on it, an elastic cord rather
/// than a robot's cable (and `EA` was typed in kN or another unit).
pub const MIN_STIFFNESS_TO_WEIGHT: f64 = 10.0;

/// A platform's or a cable's heaviness as a user knows it: a mass or a weight
/// (for a cable, per metre).
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Heaviness {
    /// Mass, kilograms (per metre for a cable).
    MassKg(f64),
    /// Weight `m g`, newtons (per metre for a cable).
    WeightN(f64),
}

impl Heaviness {
    /// The weight, newtons: a mass times [`STANDARD_GRAVITY_M_S2`], to 12
    /// significant digits (4.4 kg: 43.164 N, not 43.16400000000001 N).
    pub fn weight_n(self) -> f64 {
        match self {
            Heaviness::MassKg(kg) => {
                let weight = kg * STANDARD_GRAVITY_M_S2;
                format!("{weight:.11e}").parse().unwrap_or(weight)
            }
            Heaviness::WeightN(n) => n,
        }
    }

    /// The number as given.
    fn value(self) -> f64 {
        match self {
            Heaviness::MassKg(v) | Heaviness::WeightN(v) => v,
        }
    }
}

/// What a new robot file is made from. Every field is optional when
/// `template` names a built-in robot (`large`, `small`): the template's value
/// is kept where none is given (its `[workspace]` only with its own anchors).
/// Without a template the anchors, the attachments, the platform and the
/// cable are needed.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct RobotInit {
    /// A built-in robot to start from (`large` or `small`).
    pub template: Option<String>,
    /// The robot's name (default: the template's, else `robot`).
    pub name: Option<String>,
    /// The anchors (pulley exit points) of cables 1..4, world frame, metres.
    pub anchors_m: Vec<[f64; 3]>,
    /// The attachment points of cables 1..4, platform frame, metres.
    pub attachments_m: Vec<[f64; 3]>,
    /// The platform's mass or weight (with its payload).
    pub platform: Option<Heaviness>,
    /// The cables' mass or weight per metre.
    pub cable: Option<Heaviness>,
    /// The cables' axial stiffness `EA`, newtons (`None`: inextensible).
    pub axial_stiffness_n: Option<f64>,
    /// The centre of mass, platform frame, metres (default: the platform frame's origin).
    pub com_offset_m: Option<[f64; 3]>,
    /// The cable with the load cell, 1-based (default 1).
    pub reference_cable: Option<usize>,
    /// The box of platform positions calibration poses are drawn from.
    pub workspace: Option<Workspace>,
}

/// One input of [`RobotInit`], named in messages as its front end spells it.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum InitInput {
    /// [`RobotInit::template`].
    Template,
    /// [`RobotInit::anchors_m`].
    Anchor,
    /// [`RobotInit::attachments_m`].
    Attachment,
    /// [`RobotInit::platform`] as a mass.
    PlatformMass,
    /// [`RobotInit::platform`] as a weight.
    PlatformWeight,
    /// [`RobotInit::cable`] as a mass per metre.
    CableMass,
    /// [`RobotInit::cable`] as a weight per metre.
    CableWeight,
    /// [`RobotInit::axial_stiffness_n`].
    AxialStiffness,
    /// [`RobotInit::com_offset_m`].
    ComOffset,
    /// [`RobotInit::reference_cable`].
    ReferenceCable,
    /// [`RobotInit::workspace`].
    Workspace,
}

impl InitInput {
    /// The flag (`--anchor`) or the Python keyword (`anchors_m`).
    pub fn named(self, front_end: FrontEnd) -> &'static str {
        let (flag, keyword) = match self {
            InitInput::Template => ("--from-template", "from_template"),
            InitInput::Anchor => ("--anchor", "anchors_m"),
            InitInput::Attachment => ("--attachment", "attachments_m"),
            InitInput::PlatformMass => ("--platform-mass-kg", "platform_mass_kg"),
            InitInput::PlatformWeight => ("--platform-weight-n", "platform_weight_n"),
            InitInput::CableMass => ("--cable-mass-per-m-kg", "cable_mass_per_m_kg"),
            InitInput::CableWeight => ("--cable-weight-n-per-m", "cable_weight_n_per_m"),
            InitInput::AxialStiffness => ("--axial-stiffness-n", "axial_stiffness_n"),
            InitInput::ComOffset => ("--com-offset-m", "com_offset_m"),
            InitInput::ReferenceCable => ("--reference-cable", "reference_cable"),
            InitInput::Workspace => ("--workspace", "workspace"),
        };
        match front_end {
            FrontEnd::Cli => flag,
            FrontEnd::Python => keyword,
        }
    }
}

/// A new robot file: its text and the robot it holds.
#[derive(Debug, Clone, PartialEq)]
pub struct NewRobotFile {
    /// The file's text (TOML with a comment on every key).
    pub text: String,
    /// The robot, as [`Robot::from_file`] reads the text.
    pub robot: Robot,
}

/// The robot file `init` describes (module docs): its commented text and the
/// robot, after every check. A refusal is [`Error::InvalidInput`] naming the
/// input as `front_end` spells it.
pub fn robot_file_text(init: &RobotInit, front_end: FrontEnd) -> Result<NewRobotFile> {
    let namer = Namer { init, front_end };
    let resolved = resolve(init, &namer)?;
    check_magnitudes(&resolved.file, &namer)?;
    let label = Path::new("<new robot>");
    let robot = Robot::try_from_file_contents(resolved.file.clone(), label).map_err(|e| match e {
        Error::Robot { message, .. } => namer.refusal(&message),
        other => other,
    })?;
    let text = commented_text(&resolved.file, &resolved.notes);
    read_back(&text, &resolved.file, &robot)?;
    Ok(NewRobotFile { text, robot })
}

/// [`robot_file_text`], written to `path` (atomically); an existing file is
/// refused unless `force`. Nothing is written on any error.
pub fn write_robot_file(init: &RobotInit, front_end: FrontEnd, path: &Path, force: bool) -> Result<NewRobotFile> {
    let new = robot_file_text(init, front_end)?;
    if !force && std::fs::symlink_metadata(path).is_ok() {
        let switch = match front_end {
            FrontEnd::Cli => "--force",
            FrontEnd::Python => "force=True",
        };
        return Err(Error::InvalidInput(format!(
            "{} exists: refusing to overwrite it ({switch} replaces it)",
            path.display()
        )));
    }
    write_atomically(path, new.text.as_bytes())?;
    Ok(new)
}

/// How the messages name the inputs.
struct Namer<'a> {
    init: &'a RobotInit,
    front_end: FrontEnd,
}

impl Namer<'_> {
    /// `--platform-mass-kg 34`, or `(the large template's)` for a value the
    /// template gave, `(default)` for one neither given nor from a template.
    fn given(&self, input: InitInput, value: Option<String>) -> String {
        let name = input.named(self.front_end);
        match (value, &self.init.template) {
            (Some(value), _) => format!("{name} {value}"),
            (None, Some(template)) => format!("{name} (the {template} template's)"),
            (None, None) => format!("{name} (default)"),
        }
    }

    fn platform(&self) -> String {
        match self.init.platform {
            Some(Heaviness::MassKg(v)) => self.given(InitInput::PlatformMass, Some(shown(v))),
            Some(Heaviness::WeightN(v)) => self.given(InitInput::PlatformWeight, Some(shown(v))),
            None => self.given(InitInput::PlatformMass, None),
        }
    }

    fn cable(&self) -> String {
        match self.init.cable {
            Some(Heaviness::MassKg(v)) => self.given(InitInput::CableMass, Some(shown(v))),
            Some(Heaviness::WeightN(v)) => self.given(InitInput::CableWeight, Some(shown(v))),
            None => self.given(InitInput::CableMass, None),
        }
    }

    /// An input given as a list of points, or the template's.
    fn points(&self, input: InitInput, points: &[[f64; 3]]) -> String {
        if points.is_empty() {
            return self.given(input, None);
        }
        input.named(self.front_end).to_string()
    }

    fn simple<T: std::fmt::Display>(&self, input: InitInput, value: Option<T>) -> String {
        self.given(input, value.map(|v| v.to_string()))
    }

    fn number(&self, input: InitInput, value: Option<f64>) -> String {
        self.given(input, value.map(shown))
    }

    /// The refusal of a robot the crate's checks reject: the inputs the
    /// message speaks of (by the fields it names), then the message.
    fn refusal(&self, message: &str) -> Error {
        let init = self.init;
        let workspace = init.workspace.map(|w| {
            format!(
                "{},{},{},{},{},{}",
                w.min_m[0], w.max_m[0], w.min_m[1], w.max_m[1], w.min_m[2], w.max_m[2]
            )
        });
        // The fields each input sets, as the crate's messages name them.
        let candidates: [(&[&str], String); 7] = [
            (&["`platform_weight_n`"], self.platform()),
            (&["`cable_weight_n_per_m`"], self.cable()),
            (
                &["anchors:", "coincident anchors", "its anchor at"],
                self.points(InitInput::Anchor, &init.anchors_m),
            ),
            (
                &["coincident attachment points"],
                self.points(InitInput::Attachment, &init.attachments_m),
            ),
            (&["`workspace`"], self.given(InitInput::Workspace, workspace)),
            (
                &["axial_stiffness_n"],
                self.number(InitInput::AxialStiffness, init.axial_stiffness_n),
            ),
            (
                &["reference_cable"],
                self.simple(InitInput::ReferenceCable, init.reference_cable),
            ),
        ];
        let named: Vec<String> = candidates
            .into_iter()
            .filter(|(markers, _)| markers.iter().any(|m| message.contains(m)))
            .map(|(_, name)| name)
            .collect();
        if named.is_empty() {
            return Error::InvalidInput(message.to_string());
        }
        Error::InvalidInput(format!("{}: {message}", named.join(" and ")))
    }

    /// A refusal of one input, with what was given.
    fn refuse(&self, input: InitInput, message: String) -> Error {
        Error::InvalidInput(format!("{}: {message}", input.named(self.front_end)))
    }
}

/// The robot file's contents and what the comments say of how values were given.
struct Resolved {
    file: RobotFile,
    notes: Notes,
}

/// The file `init` describes, each input checked on its own (counts, finite
/// numbers, signs); the template's values where none is given.
fn resolve(init: &RobotInit, namer: &Namer) -> Result<Resolved> {
    let template = match &init.template {
        Some(name) => Some(
            Robot::builtin(name)
                .map_err(|_| {
                    namer.refuse(
                        InitInput::Template,
                        format!("`{name}` is not a built-in robot (large, small)"),
                    )
                })?
                .to_file_contents(),
        ),
        None => None,
    };
    let missing = |input: InitInput, what: &str| {
        namer.refuse(
            input,
            format!(
                "missing: give {what}, or start from a built-in robot with {} large|small",
                InitInput::Template.named(namer.front_end)
            ),
        )
    };
    let anchors = points(namer, InitInput::Anchor, &init.anchors_m)?;
    let attachments = points(namer, InitInput::Attachment, &init.attachments_m)?;
    let cables = match (anchors, attachments, &template) {
        (Some(a), Some(b), _) => (0..CABLE_COUNT)
            .map(|i| CableEntry {
                anchor_m: a[i],
                attachment_m: b[i],
            })
            .collect(),
        (a, b, Some(t)) => t
            .cables
            .iter()
            .enumerate()
            .map(|(i, c)| CableEntry {
                anchor_m: a.map_or(c.anchor_m, |a| a[i]),
                attachment_m: b.map_or(c.attachment_m, |b| b[i]),
            })
            .collect(),
        (None, _, None) => {
            return Err(missing(
                InitInput::Anchor,
                "the four anchors (x,y,z, world frame, m) in cable order",
            ))
        }
        (_, None, None) => {
            return Err(missing(
                InitInput::Attachment,
                "the four attachment points (x,y,z, platform frame, m) in cable order",
            ))
        }
    };
    let platform_weight_n = match (init.platform, &template) {
        (Some(h), _) => positive(namer, h, platform_input(h), true)?,
        (None, Some(t)) => t.platform_weight_n,
        (None, None) => {
            let what = format!(
                "the platform's mass in kg (or its weight in N with {})",
                InitInput::PlatformWeight.named(namer.front_end)
            );
            return Err(missing(InitInput::PlatformMass, &what));
        }
    };
    let cable_weight_n_per_m = match (init.cable, &template) {
        (Some(h), _) => positive(namer, h, cable_input(h), false)?,
        (None, Some(t)) => t.cable_weight_n_per_m,
        (None, None) => {
            let what = format!(
                "the cables' mass per metre in kg (or their weight per metre in N with {})",
                InitInput::CableWeight.named(namer.front_end)
            );
            return Err(missing(InitInput::CableMass, &what));
        }
    };
    let file = RobotFile {
        name: init
            .name
            .clone()
            .or_else(|| template.as_ref().map(|t| t.name.clone()))
            .unwrap_or_else(|| "robot".into()),
        paper_robot: None,
        reference_cable: reference_cable(init, namer, template.as_ref())?,
        platform_weight_n,
        cable_weight_n_per_m,
        com_offset_m: com_offset(init, namer, template.as_ref())?,
        cables,
        length_offsets_m: None,
        workspace: workspace(init, template.as_ref()),
        effects: effects(init, namer)?,
        calibration: None,
    };
    let notes = Notes {
        platform: mass_note(init.platform, "kg"),
        cable: mass_note(init.cable, "kg/m"),
        template: init.template.clone(),
    };
    Ok(Resolved { file, notes })
}

/// ` (4.4 kg x 9.81 m/s^2)` for a weight given as a mass.
fn mass_note(h: Option<Heaviness>, unit: &str) -> String {
    match h {
        Some(Heaviness::MassKg(kg)) => format!(" ({kg} {unit} x {STANDARD_GRAVITY_M_S2} m/s^2)"),
        _ => String::new(),
    }
}

fn platform_input(h: Heaviness) -> InitInput {
    match h {
        Heaviness::MassKg(_) => InitInput::PlatformMass,
        Heaviness::WeightN(_) => InitInput::PlatformWeight,
    }
}

fn cable_input(h: Heaviness) -> InitInput {
    match h {
        Heaviness::MassKg(_) => InitInput::CableMass,
        Heaviness::WeightN(_) => InitInput::CableWeight,
    }
}

/// A weight from a heaviness: finite, positive (zero allowed for a cable: the massless limit).
fn positive(namer: &Namer, h: Heaviness, input: InitInput, strictly: bool) -> Result<f64> {
    let v = h.value();
    let ok = v.is_finite() && if strictly { v > 0.0 } else { v >= 0.0 };
    if !ok {
        let sign = if strictly { "positive" } else { "zero or positive" };
        return Err(namer.refuse(input, format!("{v} is not a {sign} finite number")));
    }
    Ok(h.weight_n())
}

/// The four points of `input`, or `None` when none are given; finite numbers, one point per cable.
fn points(namer: &Namer, input: InitInput, given: &[[f64; 3]]) -> Result<Option<[[f64; 3]; CABLE_COUNT]>> {
    if given.is_empty() {
        return Ok(None);
    }
    let once = match namer.front_end {
        FrontEnd::Cli => "once per cable",
        FrontEnd::Python => "one row per cable",
    };
    if given.len() != CABLE_COUNT {
        return Err(namer.refuse(
            input,
            format!(
                "{} given: sagcal models a suspended robot with {CABLE_COUNT} cables, so give x,y,z {once}, in cable order",
                match given.len() {
                    1 => "1 point".to_string(),
                    n => format!("{n} points"),
                }
            ),
        ));
    }
    if let Some(i) = given.iter().position(|p| !p.iter().all(|v| v.is_finite())) {
        return Err(namer.refuse(
            input,
            format!("cable {}: {:?} is not three finite numbers", i + 1, given[i]),
        ));
    }
    Ok(Some(std::array::from_fn(|i| given[i])))
}

fn reference_cable(init: &RobotInit, namer: &Namer, template: Option<&RobotFile>) -> Result<usize> {
    match init.reference_cable {
        Some(k) if (1..=CABLE_COUNT).contains(&k) => Ok(k),
        Some(k) => Err(namer.refuse(
            InitInput::ReferenceCable,
            format!("cable {k} does not exist: cables are numbered 1..{CABLE_COUNT} in the order of the anchors"),
        )),
        None => Ok(template.map_or(1, |t| t.reference_cable)),
    }
}

fn com_offset(init: &RobotInit, namer: &Namer, template: Option<&RobotFile>) -> Result<[f64; 3]> {
    match init.com_offset_m {
        Some(c) if c.iter().all(|v| v.is_finite()) => Ok(c),
        Some(c) => Err(namer.refuse(InitInput::ComOffset, format!("{c:?} is not three finite numbers"))),
        None => Ok(template.map_or([0.0; 3], |t| t.com_offset_m)),
    }
}

/// The workspace given, else the template's when its anchors are kept.
fn workspace(init: &RobotInit, template: Option<&RobotFile>) -> Option<WorkspaceEntry> {
    match init.workspace {
        Some(w) => Some(WorkspaceEntry {
            min_m: w.min_m,
            max_m: w.max_m,
        }),
        None if init.anchors_m.is_empty() => template.and_then(|t| t.workspace),
        None => None,
    }
}

fn effects(init: &RobotInit, namer: &Namer) -> Result<Option<crate::model::effects::Effects>> {
    let Some(ea) = init.axial_stiffness_n else {
        return Ok(None);
    };
    if !(ea.is_finite() && ea > 0.0) {
        return Err(namer.refuse(
            InitInput::AxialStiffness,
            format!("{ea} is not a positive finite stiffness EA in newtons"),
        ));
    }
    Ok(Some(crate::model::effects::Effects {
        axial_stiffness_n: Some(ea),
        ..Default::default()
    }))
}

/// This module's checks of magnitudes typed by hand (module docs), before
/// the crate's checks: they name the likelier mistake.
fn check_magnitudes(file: &RobotFile, namer: &Namer) -> Result<()> {
    let anchors: [Vector3<f64>; CABLE_COUNT] = std::array::from_fn(|i| Vector3::from(file.cables[i].anchor_m));
    let attachments: Vec<Vector3<f64>> = file.cables.iter().map(|c| Vector3::from(c.attachment_m)).collect();
    let spread_m = (0..CABLE_COUNT)
        .flat_map(|i| (i + 1..CABLE_COUNT).map(move |j| (anchors[i] - anchors[j]).norm()))
        .fold(0.0, f64::max);
    if spread_m > MAX_ANCHOR_SPREAD_M {
        return Err(Error::InvalidInput(format!(
            "{}: anchors {spread_m:.4e} m apart, more than {MAX_ANCHOR_SPREAD_M} m: larger than any robot hung from \
             cables (the FAST telescope's feed cabin hangs from towers on a 600 m circle); the anchors are in metres \
             (typed in millimetres?)",
            namer.points(InitInput::Anchor, &namer.init.anchors_m)
        )));
    }
    let footprint = Footprint::of_anchors(&anchors);
    // The platform's reach, as `geometry::platform_reach_m` measures it.
    let reach_m = attachments.iter().map(|b| b.norm()).fold(0.0, f64::max);
    // Anchors on a line are `geometry::check_robot`'s to name.
    let surround = footprint.width_m > MIN_FOOTPRINT_WIDTH_FRACTION * footprint.diameter_m;
    if surround && 2.0 * reach_m >= footprint.width_m {
        return Err(Error::InvalidInput(format!(
            "{}: an attachment point is {reach_m:.4} m from the platform's origin, so the platform is {:.4} m across, \
             as wide as the anchors' footprint ({:.4} m) or wider: a platform as wide as the space between its anchors \
             cannot move in it; the attachment points are in metres in the platform frame (typed in millimetres?)",
            namer.points(InitInput::Attachment, &namer.init.attachments_m),
            2.0 * reach_m,
            footprint.width_m
        )));
    }
    let radius_m = attachments.iter().map(|b| b.x.hypot(b.y)).fold(0.0, f64::max);
    let com = Vector3::from(file.com_offset_m);
    if com.x.hypot(com.y) > radius_m {
        return Err(Error::InvalidInput(format!(
            "{}: the centre of mass is {:.4} m from the platform's origin horizontally, beyond its attachment points \
             ({radius_m:.4} m): a payload whose weight acts outside the points its cables hold would tip off the \
             platform; the centre of mass is in metres in the platform frame",
            namer.simple(
                InitInput::ComOffset,
                namer.init.com_offset_m.map(|c| format!("{},{},{}", c[0], c[1], c[2]))
            ),
            com.x.hypot(com.y)
        )));
    }
    if let Some(ea) = file.effects.and_then(|e| e.axial_stiffness_n) {
        let least = MIN_STIFFNESS_TO_WEIGHT * file.platform_weight_n;
        if ea < least {
            return Err(Error::InvalidInput(format!(
                "{}: EA = {ea} N is below {MIN_STIFFNESS_TO_WEIGHT} times the platform's weight ({least:.4e} N): such \
                 a cable stretches more than a tenth of its length under the platform, an elastic cord rather than a \
                 robot's cable; EA (Young's modulus times the cross-section) is in newtons (typed in kN?)",
                namer.number(InitInput::AxialStiffness, Some(ea))
            )));
        }
    }
    Ok(())
}

/// The text read back must give the same file and the same robot, to the last bit.
fn read_back(text: &str, file: &RobotFile, robot: &Robot) -> Result<()> {
    let parsed: RobotFile = toml::from_str(text)
        .map_err(|e| Error::InvalidInput(format!("the new robot file does not read back as TOML: {e}")))?;
    let again = Robot::try_from_file_contents(parsed.clone(), Path::new("<new robot, read back>"))?;
    if &parsed != file || &again != robot {
        return Err(Error::InvalidInput(
            "the new robot file does not read back to the same robot".into(),
        ));
    }
    Ok(())
}

/// A number as a user types it: `4.4`, `20`, `1e-7`, `3e6` (not `0.0000001`, `3000000`).
fn shown(v: f64) -> String {
    if v == 0.0 || (1e-4..1e6).contains(&v.abs()) {
        v.to_string()
    } else {
        format!("{v:e}")
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn small_lab() -> RobotInit {
        RobotInit {
            template: Some("small".into()),
            anchors_m: vec![
                [-5.0, -2.0, 20.0],
                [5.0, -2.0, 20.0],
                [5.0, 2.0, 20.0],
                [-5.0, 2.0, 20.0],
            ],
            ..RobotInit::default()
        }
    }

    #[test]
    fn a_template_keeps_its_workspace_only_with_its_own_anchors() {
        let kept = robot_file_text(
            &RobotInit {
                template: Some("small".into()),
                ..RobotInit::default()
            },
            FrontEnd::Cli,
        )
        .unwrap();
        assert_eq!(kept.robot.workspace, Robot::builtin("small").unwrap().workspace);
        let moved = robot_file_text(&small_lab(), FrontEnd::Cli).unwrap();
        assert_eq!(moved.robot.workspace, None);
        assert!(moved.text.contains("# No [workspace]"));
    }

    #[test]
    fn a_mass_is_weighed_to_twelve_digits() {
        assert_eq!(Heaviness::MassKg(4.4).weight_n(), 43.164);
        assert_eq!(Heaviness::MassKg(0.0724).weight_n(), 0.710244);
        assert_eq!(Heaviness::WeightN(43.16400000000001).weight_n(), 43.16400000000001);
    }

    #[test]
    fn refusals_name_the_input_as_the_front_end_spells_it() {
        let init = RobotInit {
            platform: Some(Heaviness::WeightN(-1.0)),
            ..small_lab()
        };
        let cli = robot_file_text(&init, FrontEnd::Cli).unwrap_err().to_string();
        assert!(cli.contains("--platform-weight-n: -1 is not a positive"), "{cli}");
        let python = robot_file_text(&init, FrontEnd::Python).unwrap_err().to_string();
        assert!(python.contains("platform_weight_n: -1 is not a positive"), "{python}");
        // A value the template gave is named as the template's: four 10.8 m
        // cables of 0.100062 N/m weigh 110 times a 4 g platform.
        let init = RobotInit {
            platform: Some(Heaviness::MassKg(4e-3)),
            ..small_lab()
        };
        let message = robot_file_text(&init, FrontEnd::Cli).unwrap_err().to_string();
        assert!(
            message.contains("--platform-mass-kg 0.004 and --cable-mass-per-m-kg (the small template's)"),
            "{message}"
        );
    }
}
