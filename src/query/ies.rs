//! An IES profile on its own, outside any light: the candela lookup that both backends make,
//! for reports and candela plots of a file.

use glam::DVec3;

use crate::prepare::ies::Profile;

impl Profile {
    /// The profile's candela toward light-space unit direction `e_local` (nadir = −Z, C0 = +X,
    /// DESIGN.md §6 I2), after `ies:angleScale` (0 leaves the angles as they are), before
    /// `ies:normalize` and the tilt factor: the f64 lookup of the reference (§6 I3), 0 outside
    /// the profile's grid.
    pub fn candela(&self, e_local: DVec3, angle_scale: f64) -> f64 {
        crate::cpu::ies::ies_factor(self, e_local, angle_scale)
    }
}
