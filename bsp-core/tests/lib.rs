//! Integration tests of `bsp-core`, one binary: the exact kernel,
//! splitting, trees and real meshes, checked against an independent
//! big-rational oracle and brute-force ray casting.
//!
//! The modules live in `suite/` rather than next to this file because
//! Cargo would build every `tests/*.rs` as a test binary of its own.

#[path = "suite/classify.rs"]
mod classify;
#[path = "suite/csg.rs"]
mod csg;
#[path = "suite/grid.rs"]
mod grid;
#[path = "suite/import.rs"]
mod import;
#[path = "suite/meshes.rs"]
mod meshes;
#[path = "suite/oracle.rs"]
mod oracle;
#[path = "suite/split.rs"]
mod split;
#[path = "suite/strategies.rs"]
mod strategies;
#[path = "suite/tree.rs"]
mod tree;
