//! tiling's integration tests, one binary: each module is one subject.

mod conservative;
mod fuzzcase;
mod pipeline;
mod scratch;
