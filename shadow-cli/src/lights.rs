//! Lights from the command line: the flags that give them, and the
//! messages about them. Placing them on the grid is `svbsp`'s
//! ([`svbsp::place_lights`]).

use anyhow::{Result, anyhow};
use bsp_core::{FaceDefect, Grid};
use glam::DVec3;
use svbsp::{AreaLightError, Light, LightError, LightSpec, PlacedLight, SoftLight, SoftSpec};

/// `x,y,z` with the shortest representation of each coordinate.
pub(crate) fn fmt_input(v: DVec3) -> String {
    svbsp::input_triple(v)
}

/// The flag that gives a light, as typed.
pub(crate) fn flag(spec: &LightSpec) -> String {
    match spec {
        LightSpec::Point(p) => format!("--light {}", fmt_input(*p)),
        LightSpec::Sun(d) => format!("--sun {}", fmt_input(*d)),
    }
}

/// An error about the lights, naming the light by its number and flag
/// (`specs`, then `soft`).
/// (`grid`: the grid the lights were placed on, once there is one.)
fn explain(
    e: LightError,
    grid: Option<&Grid>,
    specs: &[LightSpec],
    soft: &[SoftSpec],
) -> anyhow::Error {
    let at = |i: usize| match specs.get(i) {
        Some(s) => format!("light {i} ({})", flag(s)),
        None => format!("light {i} ({})", soft[i - specs.len()]),
    };
    match e {
        LightError::FarPoint {
            index,
            reach,
            centre,
        } => anyhow!(
            "{}: outside the grid shared with the scene: a point light may lie at most \
             {reach:.3e} units from {} along each axis; give a distant light as --sun X,Y,Z",
            at(index),
            fmt_input(centre)
        ),
        LightError::ZeroSun { index } => anyhow!("{}: the sun direction is zero", at(index)),
        LightError::Extent {
            index,
            cause: AreaLightError::Shape(FaceDefect::NonPlanar),
        } if index >= specs.len()
            && let Some(grid) = grid =>
        {
            // how far from flat, as given and as snapped: a tilted
            // polygon's corners written in decimals seldom lie in one
            // plane once snapped, even where they nearly do as given
            let SoftSpec::Area(corners) = &soft[index - specs.len()] else {
                unreachable!("only an area light has corners")
            };
            let snapped: Vec<DVec3> = (corners.iter())
                .map(|&c| grid.snap(c).map_or(c, |g| grid.to_world(g.map(f64::from))))
                .collect();
            anyhow!(
                "{}: its corners are not in one plane: they lie up to {:.3e} units off their \
                 plane as given, {:.3e} once snapped to the grid (step {}); give a triangle, or \
                 corners whose plane holds them exactly (an axis-aligned rectangle, say)",
                at(index),
                off_plane(corners),
                off_plane(&snapped),
                grid.step_text()
            )
        }
        LightError::Extent { index, cause } => anyhow!("{}: {cause}", at(index)),
        e => anyhow!(e),
    }
}

/// The farthest any of `corners` lies from their plane (Newell's normal
/// through their centroid).
fn off_plane(corners: &[DVec3]) -> f64 {
    let c = corners.iter().sum::<DVec3>() / corners.len() as f64;
    let centred: Vec<DVec3> = corners.iter().map(|&p| p - c).collect();
    let n = shadow_scene::unit_or_zero(shadow_scene::newell(&centred));
    corners
        .iter()
        .map(|&p| (p - c).dot(n).abs())
        .fold(0.0, f64::max)
}

/// The grid shared by the scene and its point lights and area lights'
/// corners (see [`svbsp::shared_grid`]).
pub(crate) fn shared_grid(
    positions: &[DVec3],
    specs: &[LightSpec],
    soft: &[SoftSpec],
) -> Result<Grid> {
    svbsp::shared_soft_grid(positions, specs, soft).map_err(|e| explain(e, None, specs, soft))
}

/// Every light on `grid`, errors naming the light and its flag: the
/// point lights and suns, and where lights with extent are given, every
/// light as one for soft shadows.
pub(crate) fn place_lights(
    grid: &Grid,
    specs: &[LightSpec],
    soft: &[SoftSpec],
) -> Result<(Vec<PlacedLight>, Vec<SoftLight>)> {
    let placed =
        svbsp::place_lights(grid, specs).map_err(|e| explain(e, Some(grid), specs, soft))?;
    if soft.is_empty() {
        return Ok((placed, Vec::new()));
    }
    let all = svbsp::place_soft_lights(grid, &placed, soft)
        .map_err(|e| explain(e, Some(grid), specs, soft))?;
    Ok((placed, all))
}

/// A light in words: the flag that gave it and what became of it on the
/// grid (the outputs have the exact values).
pub(crate) fn describe(l: &PlacedLight) -> String {
    match l.light {
        Light::Point(_) => {
            let moved = l.world.distance(l.spec.value());
            if moved == 0.0 {
                format!("point light {}, on the grid", flag(&l.spec))
            } else {
                format!(
                    "point light {}, snapped to the grid {moved:.1e} units away",
                    flag(&l.spec)
                )
            }
        }
        Light::Directional(q) => format!(
            "sun {}, integer direction {},{},{}",
            flag(&l.spec),
            q[0],
            q[1],
            q[2]
        ),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn errors_name_the_light_and_its_flag() {
        let scene = [DVec3::ZERO, DVec3::ONE];
        let specs = [
            LightSpec::Point(DVec3::new(0.5, 0.5, 2.0)),
            LightSpec::Point(DVec3::new(0.5, 0.5, 1e6)),
        ];
        let g = shared_grid(&scene, &specs, &[]).unwrap();
        let e = place_lights(&g, &specs, &[]).unwrap_err().to_string();
        assert!(
            e.starts_with("light 1 (--light 0.5,0.5,1000000): outside the grid"),
            "{e}"
        );
        assert!(e.contains("--sun"), "{e}");
        let e = place_lights(&g, &[LightSpec::Sun(DVec3::ZERO)], &[])
            .unwrap_err()
            .to_string();
        assert_eq!(e, "light 0 (--sun 0,0,0): the sun direction is zero");
        let (placed, _) = place_lights(&g, &specs[..1], &[]).unwrap();
        assert_eq!(
            describe(&placed[0]),
            "point light --light 0.5,0.5,2, on the grid"
        );
    }
}
