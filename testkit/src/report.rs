//! Failure reporting: a panic naming the invariant, with the input as a Rust expression.

#[allow(unused_imports)]
use super::*;

/// Panics with `msg` and the input as a Rust expression.
#[cold]
#[track_caller]
pub(crate) fn fail(input: &dyn Debug, msg: fmt::Arguments<'_>) -> ! {
    panic!("check failed: {msg}\ninput (paste into a regression test):\n{input:?}")
}

macro_rules! ensure {
    ($input:expr, $cond:expr, $($msg:tt)+) => {
        if !$cond {
            fail($input, format_args!($($msg)+))
        }
    };
}

/// Prints a slice as `vec![a, b, c]`.
pub(crate) struct VecLit<'a, T>(pub(crate) &'a [T]);

impl<T: Debug> Debug for VecLit<'_, T> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str("vec!")?;
        f.debug_list().entries(self.0).finish()
    }
}

/// Prints a slice of vectors as `vec![vec![..], ..]`.
pub(crate) struct NestedVecLit<'a, T>(pub(crate) &'a [Vec<T>]);

impl<T: Debug> Debug for NestedVecLit<'_, T> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str("vec!")?;
        f.debug_list()
            .entries(self.0.iter().map(|v| VecLit(v)))
            .finish()
    }
}
