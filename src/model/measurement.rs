//! One static pose's measurements: what the robot's own sensors read there.
//!
//! ```
//! use sagcal::model::measurement::{ReadingSet, Sensor};
//! // Data snooping left out cable 2's encoder and the load cell of one pose.
//! let excluded = ReadingSet::NONE.with(Sensor::Encoder(1)).with(Sensor::LoadCell);
//! assert!(excluded.contains(Sensor::LoadCell) && !excluded.contains(Sensor::Encoder(0)));
//! let words: Vec<String> = excluded.iter().map(Sensor::describe).collect();
//! assert_eq!(words, ["encoder of cable 2", "load cell"]);
//! assert!(excluded.without(Sensor::Encoder(1)).without(Sensor::LoadCell).is_empty());
//! assert_eq!(Sensor::ALL.len(), 4 + 1 + 3 + 3); // encoders, load cell, localiser position and orientation
//! ```
//!
//! Rows of a measurement file are in the order the robot took them; each
//! pose then knows its row and its cables' directions of last motion:
//!
//! ```
//! use sagcal::model::measurement::{mark_time_order, PoseMeasurement, ReadingOrder};
//! let pose = |lengths: [f64; 4]| PoseMeasurement {
//!     line: 0,
//!     position_m: [0.0; 3],
//!     roll_deg: 0.0,
//!     pitch_deg: 0.0,
//!     yaw_deg: 0.0,
//!     encoder_lengths_m: lengths,
//!     reference_tension_n: 100.0,
//!     excluded: Default::default(),
//!     order: None,
//! };
//! let mut rows = vec![pose([1.0, 2.0, 3.0, 4.0]), pose([1.5, 1.0, 3.0, 4.2])];
//! mark_time_order(&mut rows);
//! assert_eq!(rows[0].order, Some(ReadingOrder { row: 1, direction: [0; 4] }));
//! assert_eq!(rows[1].order, Some(ReadingOrder { row: 2, direction: [1, -1, 0, 1] }));
//! ```

use serde::{Deserialize, Serialize};

use crate::model::pose::PlatformPose;

/// One static pose: localiser pose, encoder readings and load-cell tension.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct PoseMeasurement {
    /// 1-based line in the file it was read from (comments and blank lines
    /// counted, the header of a comment-free file is line 1); 0 for in-memory data.
    pub line: usize,
    /// Localiser position of the platform frame origin in the world frame, metres.
    pub position_m: [f64; 3],
    /// Roll angle (rotation about x, applied first), degrees.
    pub roll_deg: f64,
    /// Pitch angle (rotation about y), degrees.
    pub pitch_deg: f64,
    /// Yaw angle (rotation about z, applied last), degrees: `R = Rz(yaw) Ry(pitch) Rx(roll)`.
    pub yaw_deg: f64,
    /// Encoder readings of cables 1..4, metres: true cable length plus an
    /// unknown per-cable offset (any finite value).
    pub encoder_lengths_m: [f64; 4],
    /// Load-cell tension of the reference cable at the platform attachment, newtons (positive).
    pub reference_tension_n: f64,
    /// Readings the calibration leaves out (gross errors found by data
    /// snooping, `crate::calib::gross_errors`); empty as read from a file.
    #[serde(default, skip_serializing_if = "ReadingSet::is_empty")]
    pub excluded: ReadingSet,
    /// Where the pose stands in the order the robot took its poses in (its
    /// row and each cable's direction of last motion); `None` where that
    /// order is unknown (a RecurDyn log, an authors' folder). Set by
    /// [`mark_time_order`] for rows known to be in time order.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub order: Option<ReadingOrder>,
}

/// A pose's place in time and motion: the faults that live there (a drift
/// with the row, a friction or backlash that depends on the direction of the
/// last motion) are functions of it.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub struct ReadingOrder {
    /// The row, counted from 1 in the order the poses were taken.
    pub row: usize,
    /// Per cable (robot order): +1 when its encoder reading grew since the
    /// previous row (paid out), -1 when it shrank (reeled in), 0 for the
    /// first row (the motion that led there is unknown) or no motion.
    pub direction: [i8; 4],
}

/// Mark `measurements` as rows in the order the robot took them: row `k + 1`
/// for the `k`-th, and each cable's direction of last motion from the sign of
/// its encoder reading's change since the previous row ([`ReadingOrder`]).
pub fn mark_time_order(measurements: &mut [PoseMeasurement]) {
    let mut previous: Option<[f64; 4]> = None;
    for (k, m) in measurements.iter_mut().enumerate() {
        let direction = std::array::from_fn(|i| match previous {
            Some(before) => match m.encoder_lengths_m[i] - before[i] {
                d if d > 0.0 => 1,
                d if d < 0.0 => -1,
                _ => 0,
            },
            None => 0,
        });
        previous = Some(m.encoder_lengths_m);
        m.order = Some(ReadingOrder { row: k + 1, direction });
    }
}

impl PoseMeasurement {
    /// The localiser's reading as a pose (its position and roll, pitch, yaw).
    pub fn localiser_pose(&self) -> PlatformPose {
        PlatformPose::from_roll_pitch_yaw_deg(self.position_m.into(), self.roll_deg, self.pitch_deg, self.yaw_deg)
    }
}

/// One reading of a pose: a sensor, and for encoders and localiser axes which one.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Sensor {
    /// The encoder of cable `i` (0-based, the robot's cable order).
    Encoder(usize),
    /// The load cell on the reference cable.
    LoadCell,
    /// The localiser's position along world axis `0..3` (x, y, z).
    Position(usize),
    /// The localiser's orientation about axis `0..3` of its rotation error (x, y, z).
    Orientation(usize),
}

impl Sensor {
    /// Every reading of a pose, in a fixed order.
    pub const ALL: [Sensor; 11] = [
        Sensor::Encoder(0),
        Sensor::Encoder(1),
        Sensor::Encoder(2),
        Sensor::Encoder(3),
        Sensor::LoadCell,
        Sensor::Position(0),
        Sensor::Position(1),
        Sensor::Position(2),
        Sensor::Orientation(0),
        Sensor::Orientation(1),
        Sensor::Orientation(2),
    ];

    fn bit(self) -> u16 {
        let index = match self {
            Sensor::Encoder(i) => i.min(3),
            Sensor::LoadCell => 4,
            Sensor::Position(a) => 5 + a.min(2),
            Sensor::Orientation(a) => 8 + a.min(2),
        };
        1 << index
    }

    /// The reading in words: `encoder of cable 2`, `load cell`, `localiser x`, `localiser orientation about x`.
    pub fn describe(self) -> String {
        const AXES: [&str; 3] = ["x", "y", "z"];
        match self {
            Sensor::Encoder(i) => format!("encoder of cable {}", i + 1),
            Sensor::LoadCell => "load cell".into(),
            Sensor::Position(a) => format!("localiser {}", AXES[a.min(2)]),
            Sensor::Orientation(a) => format!("localiser orientation about {}", AXES[a.min(2)]),
        }
    }
}

/// A set of readings of one pose ([`Sensor`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Hash, Serialize, Deserialize)]
pub struct ReadingSet(u16);

impl ReadingSet {
    /// No reading.
    pub const NONE: ReadingSet = ReadingSet(0);

    /// This set and `sensor`.
    pub fn with(self, sensor: Sensor) -> Self {
        Self(self.0 | sensor.bit())
    }

    /// This set without `sensor`.
    pub fn without(self, sensor: Sensor) -> Self {
        Self(self.0 & !sensor.bit())
    }

    /// Whether `sensor` is in the set.
    pub fn contains(self, sensor: Sensor) -> bool {
        self.0 & sensor.bit() != 0
    }

    /// Whether the set is empty.
    pub fn is_empty(&self) -> bool {
        self.0 == 0
    }

    /// The readings in the set, in [`Sensor::ALL`] order.
    pub fn iter(self) -> impl Iterator<Item = Sensor> {
        Sensor::ALL.into_iter().filter(move |s| self.contains(*s))
    }
}
