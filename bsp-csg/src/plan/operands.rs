//! The two operands of an operation, a thing of each, and which of
//! their pieces the operation keeps.

use bsp_core::BoolOp;

/// One of an operation's two operands: `A`, the solid changed in place,
/// or `B`, the other.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) enum Operand {
    A,
    B,
}

impl Operand {
    /// The other operand.
    pub(super) fn other(self) -> Operand {
        match self {
            Operand::A => Operand::B,
            Operand::B => Operand::A,
        }
    }
}

/// A thing of each operand.
#[derive(Clone, Copy, Debug, Default)]
pub(super) struct Both<T> {
    pub(super) a: T,
    pub(super) b: T,
}

impl<T> Both<T> {
    /// Operand `o`'s.
    pub(super) fn get(&self, o: Operand) -> &T {
        match o {
            Operand::A => &self.a,
            Operand::B => &self.b,
        }
    }
}

impl<T: Send> Both<T> {
    /// `make(A)` and `make(B)`, each operand's on its own thread.
    pub(super) fn join(make: impl Fn(Operand) -> T + Sync) -> Both<T> {
        let (a, b) = bsp_core::par::join(|| make(Operand::A), || make(Operand::B));
        Both { a, b }
    }
}

impl<T, E> Both<Result<T, E>> {
    /// Both values, or the first error (`A`'s if both failed).
    pub(super) fn transpose(self) -> Result<Both<T>, E> {
        Ok(Both {
            a: self.a?,
            b: self.b?,
        })
    }
}

/// Which pieces an operation keeps: of each operand, by whether they lie
/// inside the other operand's solid.
#[derive(Clone, Copy, Debug)]
pub(super) struct Keep(pub(super) BoolOp);

impl Keep {
    /// Whether a piece of operand `of` stays, `inside_other` saying
    /// whether it lies inside the other operand's solid: for `a ∪ b` the
    /// pieces of each outside the other, for `a ∩ b` those inside, for
    /// `a − b` those of `a` outside `b` and those of `b` inside `a`.
    pub(super) fn piece(self, of: Operand, inside_other: bool) -> bool {
        match (of, self.0) {
            (Operand::A, BoolOp::Union | BoolOp::Difference) | (Operand::B, BoolOp::Union) => {
                !inside_other
            }
            (Operand::A, BoolOp::Intersection)
            | (Operand::B, BoolOp::Intersection | BoolOp::Difference) => inside_other,
        }
    }
}
