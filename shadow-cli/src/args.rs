//! The flags several commands share, declared once, and their parsers.

use std::path::PathBuf;

use bsp_shadows::soft_file::{parse_area_light, parse_sun_disc};
use clap::Args;
use glam::DVec3;
use shadow_raster::svg::{SvgViewpoint, ViewRequest};
pub(crate) use shadow_raster::{parse_fov, parse_size, parse_up};
pub(crate) use shadow_scene::parse_vec3;
use shadow_scene::{Mesh, Staging};
use svbsp::{LightSpec, SoftSpec};

/// Where the mesh comes from: a file or a built-in scene (exactly one).
#[derive(Args, Debug)]
pub(crate) struct SourceArgs {
    /// Mesh file (.obj, .stl, or CityJSON .json).
    pub(crate) input: Option<PathBuf>,
    /// Built-in scene instead of a file (room, chair, cube, bunny, the
    /// bunny refined to bunny-11k ... bunny-893k faces, city, city-100k).
    #[arg(long, value_name = "NAME")]
    pub(crate) scene: Option<String>,
}

impl SourceArgs {
    /// Fails unless exactly one of a file and `--scene` is given.
    pub(crate) fn check(&self) -> anyhow::Result<()> {
        match (&self.input, &self.scene) {
            (Some(_), Some(_)) => {
                anyhow::bail!("give either an INPUT file or --scene NAME, not both")
            }
            (None, None) => {
                anyhow::bail!("no input: give a mesh file (.obj, .stl, .json) or --scene NAME")
            }
            _ => Ok(()),
        }
    }

    /// The built-in scene's default camera and light, for its mesh's
    /// `bounds` ([`Staging::of_scene`]).
    pub(crate) fn staging(&self, bounds: (DVec3, DVec3)) -> Option<Staging> {
        match (&self.input, &self.scene) {
            (None, Some(name)) => Staging::of_scene(name, bounds),
            _ => None,
        }
    }
}

/// The lights: point lights, suns, area lights and sun discs, numbered
/// in that order.
#[derive(Args, Debug, Default)]
pub(crate) struct LightArgs {
    /// A point light at X,Y,Z (input units). Repeat for several lights;
    /// lights are numbered all --light first, then all --sun [default for
    /// the built-in scenes: the scene's own light].
    #[arg(long = "light", value_name = "X,Y,Z", value_parser = parse_vec3, allow_hyphen_values = true)]
    pub(crate) lights: Vec<DVec3>,
    /// A light at infinity in the direction X,Y,Z from the scene toward
    /// the light (0,0,1: straight overhead). Repeatable.
    #[arg(long = "sun", value_name = "X,Y,Z", value_parser = parse_vec3, allow_hyphen_values = true)]
    pub(crate) suns: Vec<DVec3>,
    /// An area light: a planar convex polygon, its corners in order; it
    /// shines on the side they turn counter-clockwise about. Soft
    /// shadows: lit, penumbra and umbra (`shadows`: JSON, OBJ, SVG).
    #[arg(long = "area-light", value_name = "X,Y,Z;X,Y,Z;X,Y,Z[;...]", value_parser = parse_area_light, allow_hyphen_values = true)]
    pub(crate) areas: Vec<SoftSpec>,
    /// The sun as a disc toward DX,DY,DZ of angular radius DEG [default:
    /// 0.2666], bounded by an octagon that holds it: what is lit sees
    /// the whole disc, what is umbra none of it.
    #[arg(long = "sun-disc", value_name = "DX,DY,DZ[:DEG]", value_parser = parse_sun_disc, allow_hyphen_values = true)]
    pub(crate) discs: Vec<SoftSpec>,
}

impl LightArgs {
    /// The lights in their order.
    pub(crate) fn specs(&self) -> Vec<LightSpec> {
        let mut specs: Vec<LightSpec> = self.lights.iter().map(|&p| LightSpec::Point(p)).collect();
        specs.extend(self.suns.iter().map(|&d| LightSpec::Sun(d)));
        specs
    }

    /// The lights with extent in their order, after [`LightArgs::specs`].
    pub(crate) fn soft(&self) -> Vec<SoftSpec> {
        self.areas.iter().chain(&self.discs).cloned().collect()
    }
}

/// Where a picture is seen from.
#[derive(Args, Debug, Default)]
pub(crate) struct CameraArgs {
    /// Eye position [default: the built-in scene's viewpoint; else the
    /// scene framed from the front, right and above, the flags printed].
    #[arg(long, value_name = "X,Y,Z", value_parser = parse_vec3, allow_hyphen_values = true)]
    pub(crate) eye: Option<DVec3>,
    /// Point looked at [default: the centre of the scene's bounding box,
    /// or the built-in viewpoint's target].
    #[arg(long, value_name = "X,Y,Z", value_parser = parse_vec3, allow_hyphen_values = true)]
    pub(crate) target: Option<DVec3>,
    /// Up direction: x, y, z (y for most scans), -x, -y, -z or X,Y,Z
    /// [default: the built-in scene's, else z; +y when looking along z].
    #[arg(long, value_name = "AXIS|X,Y,Z", value_parser = parse_up, allow_hyphen_values = true)]
    pub(crate) up: Option<DVec3>,
}

impl CameraArgs {
    /// `true` if any camera flag is given.
    pub(crate) fn any(&self) -> bool {
        self.eye.is_some() || self.target.is_some() || self.up.is_some()
    }

    /// The viewpoint of a picture of `mesh`: the flags given, the rest
    /// from the built-in scene's `staging`, else (no `--eye`) the mesh
    /// framed from the front, right and above ([`Staging::framing`]) with
    /// `--up`'s axis up. The second value says whether it was framed so:
    /// the flags that reproduce it are then worth a note
    /// ([`viewpoint_flags`]).
    pub(crate) fn viewpoint(
        &self,
        mesh: &Mesh,
        staging: Option<Staging>,
        size: (u32, u32),
        fov_deg: f64,
    ) -> (SvgViewpoint, bool) {
        let given = ViewRequest {
            eye: self.eye,
            target: self.target,
            up: self.up,
        };
        SvgViewpoint::choose(given, &mesh.positions, staging, size, fov_deg)
    }

    /// [`CameraArgs::viewpoint`], with a note on stderr (unless `quiet`)
    /// of the flags that reproduce a framed camera.
    pub(crate) fn pick(
        &self,
        mesh: &Mesh,
        staging: Option<Staging>,
        (size, fov_deg): ((u32, u32), f64),
        quiet: bool,
    ) -> SvgViewpoint {
        let (at, framed) = self.viewpoint(mesh, staging, size, fov_deg);
        // (a framed eye beyond f64's range is refused by the caller)
        if framed && !quiet && at.eye.is_finite() {
            let bounds = mesh.bounds().unwrap_or_default();
            eprintln!("note: camera {}", viewpoint_flags(&at, bounds));
            // most scans are Y-up: a mesh taller along y than along z may be
            // one (a hint only: the axes of a file are its own)
            let ext = bounds.1 - bounds.0;
            if self.up.is_none() && ext.y > ext.z {
                eprintln!(
                    "note: the mesh is taller along y than along z; if it is Y-up, add --up y"
                );
            }
        }
        at
    }
}

/// `--eye X,Y,Z --target X,Y,Z --up X,Y,Z`: the flags that give `at`.
pub(crate) fn viewpoint_flags(at: &SvgViewpoint, bounds: (DVec3, DVec3)) -> String {
    let v = |p: DVec3| format!("{},{},{}", p.x, p.y, p.z);
    let target = at.target.unwrap_or((bounds.0 + bounds.1) * 0.5);
    let mut s = format!("--eye {} --target {}", v(at.eye), v(target));
    if let Some(up) = at.up {
        s += &format!(" --up {}", v(up));
    }
    s
}

/// The picture size when none is given.
const DEFAULT_SIZE: &str = "1280x720";
/// The field of view when none is given, in degrees.
const DEFAULT_FOV: f64 = 50.0;

/// The size and field of view of a picture (SVG or PNG frames).
#[derive(Args, Debug)]
pub(crate) struct ImageArgs {
    /// Picture size in pixels, the same flag as `render`'s.
    #[arg(long, value_name = "WxH", default_value = DEFAULT_SIZE, value_parser = parse_size)]
    pub(crate) size: (u32, u32),
    /// The width alone (overrides --size's).
    #[arg(long, hide = true, value_parser = clap::value_parser!(u32).range(1..=shadow_raster::MAX_SIZE as i64))]
    pub(crate) width: Option<u32>,
    /// The height alone (overrides --size's).
    #[arg(long, hide = true, value_parser = clap::value_parser!(u32).range(1..=shadow_raster::MAX_SIZE as i64))]
    pub(crate) height: Option<u32>,
    /// Vertical field of view in degrees (between 1 and 170).
    #[arg(long, value_name = "DEG", default_value_t = DEFAULT_FOV, value_parser = parse_fov)]
    pub(crate) fov: f64,
}

impl ImageArgs {
    /// `true` if a size or field of view other than the default is given.
    pub(crate) fn any(&self) -> bool {
        Ok(self.size()) != parse_size(DEFAULT_SIZE) || self.fov != DEFAULT_FOV
    }

    /// Width and height.
    pub(crate) fn size(&self) -> (u32, u32) {
        (
            self.width.unwrap_or(self.size.0),
            self.height.unwrap_or(self.size.1),
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn vectors_parse_with_clear_errors() {
        assert_eq!(
            parse_vec3("1,-2.5, 3e1").unwrap(),
            DVec3::new(1.0, -2.5, 30.0)
        );
        assert_eq!(
            parse_vec3("1,2").unwrap_err(),
            "expected three comma-separated numbers X,Y,Z, got 2 value(s)"
        );
        assert_eq!(
            parse_vec3("1,y,3").unwrap_err(),
            "`y` is not a number (expected X,Y,Z)"
        );
        assert_eq!(
            parse_vec3("1,nan,3").unwrap_err(),
            "`nan` is not a finite number"
        );
        assert!(parse_vec3("").is_err());
    }

    #[test]
    fn fov_range() {
        assert_eq!(parse_fov("60").unwrap(), 60.0);
        assert!(parse_fov("0").is_err());
        assert!(parse_fov("180").is_err());
        assert!(parse_fov("wide").is_err());
    }

    #[test]
    fn sizes_parse_with_clear_errors() {
        assert_eq!(parse_size("1920x1080"), Ok((1920, 1080)));
        assert_eq!(parse_size("64X48"), Ok((64, 48)));
        assert!(parse_size("1920").unwrap_err().contains("expected WxH"));
        assert!(
            parse_size("0x10")
                .unwrap_err()
                .contains("between 1 and 16384")
        );
        assert!(
            parse_size("axb")
                .unwrap_err()
                .contains("not a whole number")
        );
        assert!(parse_size("99999x2").unwrap_err().contains("width"));
        assert!(
            parse_size("16384x16384")
                .unwrap_err()
                .contains("pixels in all")
        );
    }
}
