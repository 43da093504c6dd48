//! Soft shadows in Python: area lights and sun discs, and the lit,
//! penumbra and umbra areas of every face (`bsp_shadows::soft_file`).

use bsp_shadows::soft_file::{SoftClass, SoftShadows as Computed};
use bsp_shadows::{DVec3, Light, SoftSpec};
use numpy::{IntoPyArray, PyArray1, PyArray2, PyArrayMethods};
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyList};

use crate::{LightError, Mesh, PointLight, Reduced, Rings, Sun, light_list, remade, run, to_py};

type Point = (f64, f64, f64);

/// An area light: a planar convex polygon, its `corners` in order; it
/// shines on the side they turn counter-clockwise about.
#[pyclass(module = "bsp_shadows", frozen)]
#[derive(Clone)]
pub(crate) struct AreaLight {
    #[pyo3(get)]
    corners: Vec<(f64, f64, f64)>,
}

#[pymethods]
impl AreaLight {
    #[new]
    fn new(corners: Vec<(f64, f64, f64)>) -> PyResult<AreaLight> {
        if corners.len() < 3 {
            return Err(LightError::new_err(format!(
                "{} corner(s): an area light takes at least three",
                corners.len()
            )));
        }
        Ok(AreaLight { corners })
    }

    fn __repr__(&self) -> String {
        format!("AreaLight({:?})", self.corners)
    }

    fn __reduce__<'py>(slf: &Bound<'py, Self>) -> Reduced<'py, (Vec<Point>,)> {
        Ok((slf.get_type().into_any(), (slf.get().corners.clone(),)))
    }
}

/// The sun as a disc toward `direction` of angular radius `radius_deg`
/// (the sun's own, 0.2666°, by default), bounded by an octagon that holds
/// it: what is lit sees the whole disc, what is umbra none of it.
#[pyclass(module = "bsp_shadows", frozen)]
#[derive(Clone)]
pub(crate) struct SunDisc {
    #[pyo3(get)]
    direction: (f64, f64, f64),
    #[pyo3(get)]
    radius_deg: f64,
}

#[pymethods]
impl SunDisc {
    #[new]
    #[pyo3(signature = (direction, radius_deg=bsp_shadows::SUN_RADIUS_DEG))]
    fn new(direction: (f64, f64, f64), radius_deg: f64) -> SunDisc {
        SunDisc {
            direction,
            radius_deg,
        }
    }

    fn __repr__(&self) -> String {
        format!(
            "SunDisc({:?}, radius_deg={})",
            self.direction, self.radius_deg
        )
    }

    fn __reduce__<'py>(slf: &Bound<'py, Self>) -> Reduced<'py, (Point, f64)> {
        let s = slf.get();
        Ok((slf.get_type().into_any(), (s.direction, s.radius_deg)))
    }
}

fn vec3((x, y, z): (f64, f64, f64)) -> DVec3 {
    DVec3::new(x, y, z)
}

/// The lit, penumbra and umbra parts of every face for some lights, at
/// least one of them with extent.
#[pyclass(module = "bsp_shadows", frozen)]
pub(crate) struct SoftShadows {
    mesh: Mesh,
    lights: Vec<Py<PyAny>>,
    /// The library's number of each light as given (points and suns
    /// first, then those with extent).
    order: Vec<usize>,
    shadows: Computed,
}

/// Shades every face of `mesh` for `lights` (at most 64 `PointLight`,
/// `Sun`, `AreaLight` or `SunDisc`): fragments each lit, in penumbra or in
/// umbra for each light, exact where their boundary is planar.
#[pyfunction]
pub(crate) fn soft_shadows(
    py: Python<'_>,
    mesh: &Mesh,
    lights: &Bound<'_, PyAny>,
) -> PyResult<SoftShadows> {
    let given: Vec<Bound<'_, PyAny>> = lights.try_iter()?.collect::<PyResult<_>>()?;
    let (mut hard, mut soft) = (Vec::new(), Vec::new());
    // each light's place among its kind, then among all
    let mut kinds = Vec::with_capacity(given.len());
    for (i, l) in given.iter().enumerate() {
        if let Ok(p) = l.cast::<PointLight>() {
            kinds.push((false, hard.len()));
            hard.push(Light::Point(vec3(p.get().position)));
        } else if let Ok(s) = l.cast::<Sun>() {
            kinds.push((false, hard.len()));
            hard.push(Light::Sun(vec3(s.get().direction)));
        } else if let Ok(a) = l.cast::<AreaLight>() {
            kinds.push((true, soft.len()));
            soft.push(SoftSpec::Area(
                a.get().corners.iter().map(|&c| vec3(c)).collect(),
            ));
        } else if let Ok(d) = l.cast::<SunDisc>() {
            kinds.push((true, soft.len()));
            let d = d.get();
            soft.push(SoftSpec::SunDisc {
                direction: vec3(d.direction),
                radius_deg: d.radius_deg,
            });
        } else {
            return Err(LightError::new_err(format!(
                "light {i} is not a PointLight, Sun, AreaLight or SunDisc"
            )));
        }
    }
    let order = (kinds.iter())
        .map(|&(extent, k)| if extent { hard.len() + k } else { k })
        .collect();
    let computed = run(py, || {
        bsp_shadows::soft_file::soft_shadows(mesh.mesh(), &hard, &soft)
    });
    Ok(SoftShadows {
        mesh: mesh.clone(),
        lights: given.into_iter().map(Bound::unbind).collect(),
        order,
        shadows: computed.map_err(to_py)?,
    })
}

impl SoftShadows {
    /// `(faces, lights)`: the area of each face in `class` of each light.
    fn areas<'py>(&self, py: Python<'py>, class: SoftClass) -> PyResult<Bound<'py, PyArray2<f64>>> {
        let (faces, lights) = (self.mesh.face_count(), self.order.len());
        let flat: Vec<f64> = (0..faces)
            .flat_map(|f| self.order.iter().map(move |&l| (f, l)))
            .map(|(f, l)| self.shadows.area_of(f, l, class))
            .collect();
        flat.into_pyarray(py).reshape([faces, lights])
    }
}

#[pymethods]
impl SoftShadows {
    /// `(faces, lights)` float64: the area of each face that sees all of
    /// each light.
    #[getter]
    fn lit_area<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray2<f64>>> {
        self.areas(py, SoftClass::Lit)
    }

    /// `(faces, lights)` float64: the area that sees part of each light
    /// (`undecided_area` included).
    #[getter]
    fn penumbra_area<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray2<f64>>> {
        self.areas(py, SoftClass::Penumbra)
    }

    /// `(faces, lights)` float64: the area that sees none of each light.
    #[getter]
    fn umbra_area<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray2<f64>>> {
        self.areas(py, SoftClass::Umbra)
    }

    /// `(faces, lights)` float64: the penumbra area that may be umbra,
    /// where an umbra boundary may be a quadric surface of three
    /// occluders' edges.
    #[getter]
    fn undecided_area<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray2<f64>>> {
        self.areas(py, SoftClass::Undecided)
    }

    /// `(faces,)` float64: each face's area.
    #[getter]
    fn face_area<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        (0..self.mesh.face_count())
            .map(|f| self.shadows.face_area(f))
            .collect::<Vec<_>>()
            .into_pyarray(py)
    }

    /// How many fragments the faces were cut into.
    #[getter]
    fn fragment_count(&self) -> usize {
        self.shadows.fragment_count()
    }

    /// Every fragment (a maximal region of one face with one class per
    /// light) as arrays, its lights in the order given: `face` (F,) int64;
    /// `lit`, `umbra`, `undecided` (F,) uint64, bit i set where light i is
    /// seen whole, not at all, or in penumbra that may be umbra (penumbra
    /// is neither lit nor umbra); `visible` (F, L) float64, the share of
    /// an area light's or a sun disc's irradiance at a penumbra fragment's
    /// centroid (of its largest convex piece), NaN elsewhere; `rings`
    /// (F+1,) int64, fragment f's rings are `rings[f]:rings[f+1]` (outer
    /// first, then holes); `ring_points` (R+1,) int64, ring r's points are
    /// `points[ring_points[r]:ring_points[r+1]]`; `points` (P, 3) float64.
    fn fragments<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let n = self.order.len();
        let given = |mask: u64| -> u64 {
            (self.order.iter().enumerate())
                .filter(|&(_, &l)| mask >> l & 1 == 1)
                .fold(0, |m, (i, _)| m | 1 << i)
        };
        let (mut face, mut lit, mut umbra, mut undecided) =
            (Vec::new(), Vec::new(), Vec::new(), Vec::new());
        let (mut visible, mut rings, mut packed) = (Vec::new(), vec![0i64], Rings::default());
        for f in self.shadows.fragments() {
            face.push(f.face as i64);
            lit.push(given(f.lit));
            umbra.push(given(f.umbra));
            undecided.push(given(f.undecided));
            (self.order.iter()).for_each(|&l| visible.push(f.visible[l].unwrap_or(f64::NAN)));
            f.rings.iter().for_each(|r| packed.push(r));
            rings.push(packed.count() as i64);
        }
        let count = face.len();
        let d = PyDict::new(py);
        d.set_item("face", face.into_pyarray(py))?;
        d.set_item("lit", lit.into_pyarray(py))?;
        d.set_item("umbra", umbra.into_pyarray(py))?;
        d.set_item("undecided", undecided.into_pyarray(py))?;
        d.set_item("visible", visible.into_pyarray(py).reshape([count, n])?)?;
        d.set_item("rings", rings.into_pyarray(py))?;
        packed.put(&d)?;
        Ok(d)
    }

    /// Writes the fragments as JSON or OBJ (groups `lit`, `penumbra`,
    /// `umbra`), by the extension, as `shadow shadows` does: its lights
    /// numbered points and suns first, then those with extent.
    fn write(&self, py: Python<'_>, path: std::path::PathBuf) -> PyResult<()> {
        run(py, || self.shadows.write(&path)).map_err(to_py)
    }

    /// The mesh shaded.
    #[getter]
    fn mesh(&self) -> Mesh {
        self.mesh.clone()
    }

    /// The lights, as given.
    #[getter]
    fn lights<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyList>> {
        light_list(py, &self.lights)
    }

    fn __repr__(&self) -> String {
        format!(
            "SoftShadows(faces={}, lights={}, fragments={})",
            self.mesh.face_count(),
            self.lights.len(),
            self.shadows.fragment_count()
        )
    }

    /// Pickled as its mesh and lights; unpickling shades again (the same
    /// bits: the result is a function of them).
    fn __reduce__<'py>(slf: &Bound<'py, Self>) -> Reduced<'py, (Mesh, Bound<'py, PyList>)> {
        remade(slf.py(), "soft_shadows", &slf.get().mesh, &slf.get().lights)
    }
}
