//! Shared by the structured targets (mesh, portals): the fuzz bytes read front to back as
//! numbers; past the end every read is 0, so every input is a complete case.

pub struct Bytes<'a>(pub &'a [u8]);

impl Bytes<'_> {
    pub fn u8(&mut self) -> u8 {
        match self.0.split_first() {
            Some((&b, rest)) => {
                self.0 = rest;
                b
            }
            None => 0,
        }
    }

    #[allow(dead_code)] // the portals target reads no i16
    pub fn i16(&mut self) -> i16 {
        i16::from_le_bytes([self.u8(), self.u8()])
    }

    /// Small values most of the time (a signed byte / 16, so that shapes have size), any f32
    /// bit pattern (non-finite and huge ones included) after a 0xFF marker.
    pub fn value(&mut self) -> f64 {
        match self.u8() {
            0xFF => f64::from(f32::from_le_bytes([
                self.u8(),
                self.u8(),
                self.u8(),
                self.u8(),
            ])),
            b => f64::from(b as i8) / 16.0,
        }
    }
}
