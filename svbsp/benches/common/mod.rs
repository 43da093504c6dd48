//! The `shadows` bench's scenes on their grids: the scenes of
//! `bsp_fixtures::scenes` (input units) snapped with one `Grid::fit_points`
//! over every vertex and every point light, and imported with
//! `import_faces`; and the process's memory.

#![allow(dead_code, unreachable_pub, missing_docs)]

use bsp_core::{Grid, Polygon, import_faces};
use glam::DVec3;
use svbsp::Light;

pub use bsp_fixtures::scenes::{SceneSpec, WorldLight, lights, scene};

/// A scene on its grid, ready for the shadows.
pub struct Prepared {
    pub name: String,
    pub grid: Grid,
    pub polys: Vec<Polygon>,
    pub lights: Vec<Light>,
    /// The lights in `f64` grid units: `true` and the point, or `false`
    /// and the sun's direction.
    pub lights_f64: Vec<(bool, DVec3)>,
}

/// Snaps the scene and its lights to one grid and imports it.
pub fn prepare(spec: &SceneSpec, world_lights: &[WorldLight]) -> Prepared {
    let mut pts: Vec<DVec3> = spec.faces.iter().flatten().copied().collect();
    for l in world_lights {
        if let WorldLight::Point(p) = l {
            pts.push(*p);
        }
    }
    let grid = Grid::fit_points(&pts).expect("scene fits a grid");
    let (polys, _report) =
        import_faces(&grid, spec.faces.iter().map(|f| &f[..])).expect("scene snaps");
    let mut lights = Vec::new();
    let mut lights_f64 = Vec::new();
    for l in world_lights {
        match l {
            WorldLight::Point(p) => {
                let g = grid.snap(*p).expect("light on the grid");
                lights.push(Light::Point(g));
                lights_f64.push((true, DVec3::new(g[0] as f64, g[1] as f64, g[2] as f64)));
            }
            WorldLight::Sun(d) => {
                lights.push(Light::Directional(*d));
                lights_f64.push((false, DVec3::new(d[0] as f64, d[1] as f64, d[2] as f64)));
            }
        }
    }
    Prepared {
        name: spec.name.clone(),
        grid,
        polys,
        lights,
        lights_f64,
    }
}

/// The process's resident memory now and its peak since the last
/// [`reset_peak`], in bytes, from `/proc/self/status` (Linux).
pub fn memory() -> Option<(u64, u64)> {
    let s = std::fs::read_to_string("/proc/self/status").ok()?;
    let field = |name: &str| -> Option<u64> {
        let line = s.lines().find(|l| l.starts_with(name))?;
        let kb: u64 = line.split_whitespace().nth(1)?.parse().ok()?;
        Some(kb * 1024)
    };
    Some((field("VmRSS:")?, field("VmHWM:")?))
}

/// Resets the peak resident memory to the current one (Linux 4.0+).
pub fn reset_peak() {
    let _ = std::fs::write("/proc/self/clear_refs", "5");
}
