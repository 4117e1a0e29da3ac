//! What `sagcal check` found, one struct that the text and the JSON both read.

use serde::Serialize;

/// `row 3 (line 5)`: a data row counted from 1 and its file line (`row 3` without one).
pub fn row_label(row: usize, line: usize) -> String {
    crate::model::DataRow {
        row,
        line: (line > 0).then_some(line),
    }
    .to_string()
}

/// What sagcal understood from a robot file and, optionally, a data file.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct CheckReport {
    /// The robot.
    pub robot: RobotSummary,
    /// The data, if a data file was given.
    pub data: Option<DataSummary>,
    /// Likely mistakes, in the order found; empty when none.
    pub warnings: Vec<CheckWarning>,
}

/// The smallest and largest value of a quantity.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Span {
    /// The smallest value.
    pub min: f64,
    /// The largest value.
    pub max: f64,
}

impl Span {
    /// The span of `values` (NaN for none).
    pub fn of(values: impl IntoIterator<Item = f64>) -> Self {
        values.into_iter().fold(
            Span {
                min: f64::NAN,
                max: f64::NAN,
            },
            |s, v| Span {
                min: s.min.min(v),
                max: s.max.max(v),
            },
        )
    }
}

/// The robot as read from its file.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct RobotSummary {
    /// The robot file, as given.
    pub path: String,
    /// The robot's name.
    pub name: String,
    /// The number of cables.
    pub cables: usize,
    /// Anchors (pulley exit points) of cables 1..4, world frame, metres.
    pub anchors_m: Vec<[f64; 3]>,
    /// Attachment points of cables 1..4, platform frame, metres.
    pub attachments_m: Vec<[f64; 3]>,
    /// The anchors' extent along world x, y and z, metres.
    pub anchor_span_m: [Span; 3],
    /// The narrowest extent of the anchors' horizontal footprint, metres.
    pub footprint_width_m: f64,
    /// The largest distance between two anchors' projections on the floor, metres.
    pub footprint_diameter_m: f64,
    /// The largest distance of an attachment point from the platform's origin, metres.
    pub platform_reach_m: f64,
    /// The cable with the load cell, 1-based.
    pub reference_cable: usize,
    /// Platform weight, newtons.
    pub platform_weight_n: f64,
    /// Platform mass at 9.81 m/s^2, kilograms.
    pub platform_mass_kg: f64,
    /// Cable weight per metre, newtons per metre.
    pub cable_weight_n_per_m: f64,
    /// Cable mass per metre at 9.81 m/s^2, grams per metre.
    pub cable_mass_g_per_m: f64,
    /// Centre of mass, platform frame, metres.
    pub com_offset_m: [f64; 3],
    /// Encoder length offsets of cables 1..4, metres (all zero in a nominal robot).
    pub length_offsets_m: [f64; 4],
    /// The box calibration poses are drawn from (`plan`, `simulate`).
    pub workspace: WorkspaceSummary,
    /// The effects the file declares (`NAME:PARAM=VALUE`, as `simulate --effect` takes them); empty: none.
    pub effects: Vec<String>,
    /// Whether the file carries a calibration's covariance (`calibrate --out` writes it; `localize` uses it).
    pub calibration_covariance: bool,
    /// Which of the paper's robots the file says it is, if any.
    pub paper_robot: Option<String>,
}

/// Where calibration poses are drawn.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct WorkspaceSummary {
    /// Lower corner, world frame, metres.
    pub min_m: [f64; 3],
    /// Upper corner, world frame, metres.
    pub max_m: [f64; 3],
    /// `robot file` (its `[workspace]`) or `derived from the anchors` (none in the file).
    pub source: String,
}

/// The data file's format, as detected.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum DataFormat {
    /// sagcal's measurement CSV (`x_m,...,f_ref_n`).
    SagcalCsv,
    /// Cable readings alone (`l1_m,l2_m,l3_m,l4_m[,f_ref_n]`), what `localize` reads.
    ReadingsOnlyCsv,
    /// A RecurDyn finite-element log.
    RecurdynLog,
    /// The dataset folder of the paper's published program.
    AuthorsFolder,
}

impl DataFormat {
    /// The format in words.
    pub fn describe(self) -> &'static str {
        match self {
            DataFormat::SagcalCsv => "sagcal CSV (x_m,y_m,z_m,roll_deg,pitch_deg,yaw_deg,l1_m..l4_m,f_ref_n)",
            DataFormat::ReadingsOnlyCsv => "readings-only CSV (l1_m..l4_m[,f_ref_n])",
            DataFormat::RecurdynLog => "RecurDyn log (x,y,z,pitch,roll,yaw,L1..L4,fc1,fz1,fh1..fh4)",
            DataFormat::AuthorsFolder => "the authors' dataset folder (pos_i, R_i, lc_meas, forces _cpp_test.csv)",
        }
    }
}

/// The data as read.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct DataSummary {
    /// The file or folder, as given.
    pub path: String,
    /// Its format.
    pub format: DataFormat,
    /// The format in words.
    pub format_description: String,
    /// Data rows read (poses, or rows of readings).
    pub rows: usize,
    /// The first and last row's file line (1-based, comments and blank lines counted).
    pub lines: Span,
    /// Rows the reader left out, with the reason (RecurDyn logs).
    pub rejected: Vec<RejectedLine>,
    /// Each measured quantity: its column, unit and range.
    pub columns: Vec<ColumnSummary>,
    /// A few rows as read, in the order of [`DataSummary::columns`].
    pub samples: Vec<SampleRow>,
    /// Which sensors the data hold.
    pub sensors: Sensors,
    /// The commands that take this data.
    pub usable_by: Vec<String>,
    /// Per cable, the encoder readings against the robot's geometry at the
    /// logged poses (files with poses only).
    pub geometry: Vec<CableAgainstGeometry>,
}

/// A row the reader left out.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct RejectedLine {
    /// Its file line (1-based).
    pub line: usize,
    /// Why.
    pub reason: String,
}

/// One measured quantity.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ColumnSummary {
    /// The column as the file names it (`x_m`, `L1`, `pos_i_cpp_test.csv x`).
    pub column: String,
    /// What it measures.
    pub quantity: String,
    /// Its unit as read.
    pub unit: String,
    /// Rows holding a value.
    pub rows: usize,
    /// Its smallest and largest value (NaN when no row holds one: `null` in JSON).
    pub range: Span,
}

/// One data row as read.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct SampleRow {
    /// The data row, counted from 1.
    pub row: usize,
    /// Its file line (1-based).
    pub line: usize,
    /// Its values, in the order of [`DataSummary::columns`] (`None`: empty field).
    pub values: Vec<Option<f64>>,
}

/// The sensors the data hold.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Sensors {
    /// Encoders (one per cable).
    pub encoders: usize,
    /// The load cell's cable (1-based), if the data have a load-cell column.
    pub load_cell_cable: Option<usize>,
    /// Rows with a load-cell reading.
    pub load_cell_rows: usize,
    /// Whether the rows carry the localiser's position.
    pub localiser_position: bool,
    /// The localiser's orientation: `measured`, `all zero` (no orientation
    /// read, or a level platform throughout) or `absent`.
    pub localiser_orientation: String,
    /// Rows with the tensions of every cable (RecurDyn logs; `verify` compares them).
    pub all_cable_tension_rows: usize,
    /// What closes the statics in words (the measurements each pose is fitted with).
    pub closure: String,
}

/// One cable's encoder readings against the distance from its anchor to its
/// attachment point at each logged pose (the robot's geometry).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct CableAgainstGeometry {
    /// The cable, 1-based.
    pub cable: usize,
    /// The median of reading minus distance, metres: the encoder's offset
    /// plus the sag (a catenary is longer than its chord).
    pub median_reading_minus_distance_m: f64,
    /// The robot file's offset of this encoder, metres.
    pub robot_offset_m: f64,
    /// The least-squares slope of the readings on the distances: about 1 when
    /// the readings follow the geometry (`None` when the distances barely vary).
    pub slope: Option<f64>,
    /// The correlation of the readings with the distances (`None` as for the slope).
    pub correlation: Option<f64>,
}

/// A likely mistake.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct CheckWarning {
    /// What kind.
    pub kind: WarningKind,
    /// What it is, naming rows (`row 3 (line 5)`), cables and columns.
    pub message: String,
    /// The data rows concerned (empty: the whole column or file).
    pub rows: Vec<crate::model::DataRow>,
}

/// The kind of a [`CheckWarning`].
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum WarningKind {
    /// A column in the wrong unit (mm for m, kN for N, ...).
    Unit,
    /// Poses outside the robot's frame (calibrate leaves them out).
    OutsideFrame,
    /// Poses outside the robot file's `[workspace]`.
    OutsideWorkspace,
    /// Encoder readings that do not follow the robot's geometry.
    Geometry,
    /// Rows calibrate would refuse (duplicates, impossible readings, angles out of range, too few rows).
    Rows,
    /// Rows the reader left out.
    Rejected,
}
