//! [`SlotMask`]: which Jacobian blocks (variable slots) of a factor a
//! linearisation is for.

/// Which Jacobian blocks (variable slots) of a factor a linearisation is for.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct SlotMask(u64);

impl SlotMask {
    /// Every slot.
    pub const ALL: SlotMask = SlotMask(u64::MAX);

    /// The slots in `slots` (slots from 64 on are always included).
    pub fn of(slots: impl IntoIterator<Item = usize>) -> Self {
        SlotMask(
            slots
                .into_iter()
                .fold(0, |mask, slot| mask | 1u64.checked_shl(slot as u32).unwrap_or(0)),
        )
    }

    /// Whether `slot` is in the mask.
    pub fn contains(self, slot: usize) -> bool {
        slot >= 64 || self.0 >> slot & 1 == 1
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn slot_masks_hold_the_slots_named_and_every_slot_from_64_on() {
        let mask = SlotMask::of([0, 2, 63]);
        let held: Vec<usize> = (0..70).filter(|&s| mask.contains(s)).collect();
        assert_eq!(held, [0, 2, 63, 64, 65, 66, 67, 68, 69]);
        assert!((0..100).all(|s| SlotMask::ALL.contains(s)));
        assert!(!SlotMask::of([]).contains(0));
    }
}
