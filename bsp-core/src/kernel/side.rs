//! The exact side of a plane.

/// Exact side of a point relative to a plane.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Side {
    /// `n · p + d > 0`.
    Front,
    /// `n · p + d < 0`.
    Back,
    /// `n · p + d = 0`.
    On,
}

impl Side {
    #[inline]
    pub(crate) fn from_sign(s: i32) -> Side {
        match s {
            1 => Side::Front,
            -1 => Side::Back,
            _ => Side::On,
        }
    }
}
