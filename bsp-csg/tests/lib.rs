//! bsp-csg's integration tests, one binary: each module is one subject.

mod certify;
mod coplanar;
mod differential;
mod drill;
mod resolve;
