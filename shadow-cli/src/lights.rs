//! Lights from the command line: point lights snapped to the grid the
//! scene is snapped to, suns quantized to integer directions.

use anyhow::{Result, anyhow, bail};
use bsp_core::{Grid, MAX_COORD};
use glam::DVec3;
use svbsp::Light;

/// A light as given on the command line, in input units.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) enum LightArg {
    /// `--light X,Y,Z`: a point light at this position.
    Point(DVec3),
    /// `--sun X,Y,Z`: a light at infinity, in this direction from the
    /// scene.
    Sun(DVec3),
}

impl LightArg {
    /// The position or direction given.
    pub(crate) fn value(&self) -> DVec3 {
        match *self {
            LightArg::Point(v) | LightArg::Sun(v) => v,
        }
    }

    /// The flag that gives this light, as typed.
    pub(crate) fn flag(&self) -> String {
        match self {
            LightArg::Point(p) => format!("--light {}", fmt_input(*p)),
            LightArg::Sun(d) => format!("--sun {}", fmt_input(*d)),
        }
    }
}

/// `x,y,z` with the shortest representation of each coordinate.
pub(crate) fn fmt_input(v: DVec3) -> String {
    format!("{},{},{}", v.x, v.y, v.z)
}

/// A light placed on the grid, with what the outputs report about it.
#[derive(Clone, Debug, PartialEq)]
pub(crate) struct SceneLight {
    /// As given.
    pub(crate) arg: LightArg,
    /// The exact light the kernel uses.
    pub(crate) light: Light,
    /// A point light's snapped position in input units; a sun's quantized
    /// direction, normalized.
    pub(crate) world: DVec3,
    /// For a sun, the angle in radians between the given and the
    /// quantized direction; zero for a point light.
    pub(crate) angle: f64,
}

/// How many times coarser (as a power of two) than the scene's own grid
/// the shared grid may become to take in the point lights. Beyond that, a
/// light far away would cost the scene its resolution: such a light is
/// outside the grid and should be a sun.
pub(crate) const LIGHT_RANGE_BITS: i32 = 8;

/// The grid shared by the scene and its point lights: the grid fitted to
/// the mesh positions and every point light, but at most
/// `2^LIGHT_RANGE_BITS` times coarser than the scene's own grid (a light
/// farther away then lies outside it, and [`place_lights`] says so).
pub(crate) fn shared_grid(positions: &[DVec3], lights: &[LightArg]) -> Result<Grid> {
    let scene =
        Grid::fit_points(positions).map_err(|e| anyhow!("cannot fit a grid to the scene: {e}"))?;
    let points: Vec<DVec3> = lights
        .iter()
        .filter_map(|l| match l {
            LightArg::Point(p) => Some(*p),
            LightArg::Sun(_) => None,
        })
        .collect();
    let coarsest = scene.scale().log2() as i32 - LIGHT_RANGE_BITS;
    match Grid::fit_points(positions.iter().chain(&points)) {
        Ok(g) if g.scale().log2() as i32 >= coarsest => Ok(g),
        _ => Grid::new(scene.origin(), coarsest)
            .map_err(|e| anyhow!("cannot fit a grid to the scene and its lights: {e}")),
    }
}

/// Snaps every point light to `grid` and quantizes every sun, in order;
/// errors name the light (numbered from 0, as in the outputs) and its flag.
pub(crate) fn place_lights(grid: &Grid, lights: &[LightArg]) -> Result<Vec<SceneLight>> {
    lights
        .iter()
        .enumerate()
        .map(|(i, arg)| {
            let at = || format!("light {i} ({})", arg.flag());
            match *arg {
                LightArg::Point(p) => {
                    // parse_vec3 admits finite values only: the light is too far
                    let g = grid.snap(p).map_err(|_| {
                        let reach = MAX_COORD as f64 / grid.scale();
                        anyhow!(
                            "{}: outside the grid shared with the scene: a point light may lie at \
                             most {reach:.3e} units from {} along each axis; give a distant light \
                             as --sun X,Y,Z",
                            at(),
                            fmt_input(grid.origin())
                        )
                    })?;
                    Ok(SceneLight {
                        arg: *arg,
                        light: Light::Point(g),
                        world: grid.to_world(g.map(f64::from)),
                        angle: 0.0,
                    })
                }
                LightArg::Sun(d) => {
                    let Some(q) = quantize_direction(d) else {
                        bail!("{}: the sun direction is zero", at());
                    };
                    let qd = DVec3::from_array(q.map(f64::from));
                    Ok(SceneLight {
                        arg: *arg,
                        light: Light::Directional(q),
                        world: qd.normalize(),
                        angle: angle_between(d, qd),
                    })
                }
            }
        })
        .collect()
}

/// The integer direction of `d`: scaled so that its largest component is
/// `±MAX_COORD`, then rounded. `None` for a zero or non-finite `d`.
pub(crate) fn quantize_direction(d: DVec3) -> Option<[i32; 3]> {
    let m = d.abs().max_element();
    if !d.is_finite() || m == 0.0 {
        return None;
    }
    // d / m has components in [-1, 1], the largest exactly ±1
    let q = (d / m * MAX_COORD as f64).round();
    Some([q.x as i32, q.y as i32, q.z as i32])
}

/// The angle between two non-zero directions, in radians (accurate for
/// tiny angles).
pub(crate) fn angle_between(a: DVec3, b: DVec3) -> f64 {
    let (a, b) = (
        (a / a.abs().max_element()).normalize(),
        (b / b.abs().max_element()).normalize(),
    );
    a.cross(b).length().atan2(a.dot(b))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sun_directions_are_quantized_to_the_grid_range() {
        let m = MAX_COORD;
        assert_eq!(quantize_direction(DVec3::Z), Some([0, 0, m]));
        assert_eq!(
            quantize_direction(DVec3::new(-2.0, 1.0, 0.0)),
            Some([-m, (m + 1) / 2, 0])
        );
        // tiny and huge directions scale alike
        assert_eq!(
            quantize_direction(DVec3::new(3e-320, 0.0, -3e-320)),
            Some([m, 0, -m])
        );
        assert_eq!(
            quantize_direction(DVec3::new(1e300, 1e300, 0.0)),
            Some([m, m, 0])
        );
        assert_eq!(quantize_direction(DVec3::ZERO), None);
        assert_eq!(quantize_direction(DVec3::new(f64::NAN, 1.0, 0.0)), None);
    }

    #[test]
    fn quantization_error_is_tiny_and_measured() {
        let d = DVec3::new(1.0, 2.0, 7.0);
        let q = quantize_direction(d).unwrap();
        let a = angle_between(d, DVec3::from_array(q.map(f64::from)));
        assert!(a > 0.0 && a < 1e-7, "{a}");
        // MAX_COORD = 3 · 22369621: thirds are exact
        let q = quantize_direction(DVec3::new(1.0, 2.0, 3.0)).unwrap();
        assert_eq!(q, [22369621, 44739242, MAX_COORD]);
        assert_eq!(angle_between(DVec3::X, DVec3::X * 7.0), 0.0);
        assert!((angle_between(DVec3::X, DVec3::Y) - std::f64::consts::FRAC_PI_2).abs() < 1e-15);
    }

    #[test]
    fn lights_share_the_scene_grid() {
        let scene = [DVec3::ZERO, DVec3::ONE];
        let near = [LightArg::Point(DVec3::new(0.5, 0.5, 3.0))];
        let g = shared_grid(&scene, &near).unwrap();
        // the light is inside the fitted box, so it snaps exactly
        let placed = place_lights(&g, &near).unwrap();
        assert_eq!(placed[0].world, DVec3::new(0.5, 0.5, 3.0));
        assert!(matches!(placed[0].light, Light::Point(_)));
        // suns do not move the grid
        let sun = [LightArg::Sun(DVec3::new(0.0, 0.0, -1e9))];
        assert_eq!(
            shared_grid(&scene, &sun).unwrap(),
            shared_grid(&scene, &[]).unwrap()
        );
        let placed = place_lights(&g, &sun).unwrap();
        assert_eq!(placed[0].light, Light::Directional([0, 0, -MAX_COORD]));
        assert_eq!(placed[0].world, DVec3::NEG_Z);
    }

    #[test]
    fn far_lights_and_zero_suns_are_errors_naming_the_light() {
        let scene = [DVec3::ZERO, DVec3::ONE];
        let lights = [
            LightArg::Point(DVec3::new(0.5, 0.5, 2.0)),
            LightArg::Point(DVec3::new(0.5, 0.5, 1e6)),
        ];
        let g = shared_grid(&scene, &lights).unwrap();
        // the grid stays at most 2^8 times coarser than the scene's own
        let own = shared_grid(&scene, &[]).unwrap();
        assert_eq!(g.scale(), own.scale() / 256.0);
        let e = place_lights(&g, &lights).unwrap_err().to_string();
        assert!(
            e.starts_with("light 1 (--light 0.5,0.5,1000000): outside the grid"),
            "{e}"
        );
        assert!(e.contains("--sun"), "{e}");
        let e = place_lights(&g, &[LightArg::Sun(DVec3::ZERO)])
            .unwrap_err()
            .to_string();
        assert_eq!(e, "light 0 (--sun 0,0,0): the sun direction is zero");
    }
}
