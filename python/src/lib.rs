//! `bsp_shadows._native`: the Python package's compiled half. Every
//! function takes numpy arrays or this module's objects, releases the GIL
//! while it works, and runs on the module's thread pool
//! (`set_threads`). `python/bsp_shadows/__init__.py` is the face people
//! use; `_native.pyi` types it.

mod soft;

use std::sync::{Arc, Mutex};

use bsp_shadows::sun::{self, HoursRun, SunSite, Up};
use bsp_shadows::{BoolOp, DVec3, Error, Face, Light};
use numpy::{
    IntoPyArray, PyArray1, PyArray2, PyArrayMethods, PyReadonlyArray1, PyReadonlyArray2,
    PyUntypedArrayMethods,
};
use pyo3::create_exception;
use pyo3::exceptions::{PyOSError, PyValueError};
use pyo3::prelude::*;
use pyo3::types::{PyBytes, PyDict, PyList};

create_exception!(
    bsp_shadows,
    BspError,
    PyValueError,
    "The base of this package's errors: input it refuses, with the library's message."
);
create_exception!(
    bsp_shadows,
    MeshError,
    BspError,
    "A mesh that cannot be used: a face naming no vertex, an operand of a Boolean that is not closed (the message names the face and the edge), a face that does not fit the grid."
);
create_exception!(
    bsp_shadows,
    LightError,
    BspError,
    "A light that cannot be placed: too far from the scene, too many, a zero direction."
);

/// What `__reduce__` gives pickle: a callable and its arguments.
type Reduced<'py, A> = PyResult<(Bound<'py, PyAny>, A)>;

/// Rings of points as arrays: every point in `points` (`(P, 3)`), ring
/// `r`'s at `points[ring_points[r]:ring_points[r + 1]]`.
struct Rings {
    ring_points: Vec<i64>,
    points: Vec<f64>,
}

impl Default for Rings {
    fn default() -> Rings {
        Rings {
            ring_points: vec![0],
            points: Vec::new(),
        }
    }
}

impl Rings {
    fn push(&mut self, ring: &[DVec3]) {
        self.points.extend(ring.iter().flat_map(|p| p.to_array()));
        self.ring_points.push((self.points.len() / 3) as i64);
    }

    /// How many rings there are.
    fn count(&self) -> usize {
        self.ring_points.len() - 1
    }

    /// Into `d` as `ring_points` and `points`.
    fn put(self, d: &Bound<'_, PyDict>) -> PyResult<()> {
        let py = d.py();
        let n = self.points.len() / 3;
        d.set_item("ring_points", self.ring_points.into_pyarray(py))?;
        d.set_item("points", self.points.into_pyarray(py).reshape([n, 3])?)
    }
}

/// Lights as given, as a Python list.
fn light_list<'py>(py: Python<'py>, lights: &[Py<PyAny>]) -> PyResult<Bound<'py, PyList>> {
    PyList::new(py, lights.iter().map(|l| l.bind(py)))
}

/// What pickle needs to make a result of `mesh` and `lights` again: the
/// native module's `function` and its arguments.
fn remade<'py>(
    py: Python<'py>,
    function: &str,
    mesh: &Mesh,
    lights: &[Py<PyAny>],
) -> Reduced<'py, (Mesh, Bound<'py, PyList>)> {
    let f = py.import("bsp_shadows._native")?.getattr(function)?;
    Ok((f, (mesh.clone(), light_list(py, lights)?)))
}

/// A Python exception for a library error, with its message.
fn to_py(e: Error) -> PyErr {
    match &e {
        Error::File(shadow_scene::SceneError::Io { .. }) | Error::Io(_) => {
            PyOSError::new_err(e.to_string())
        }
        Error::File(_) | Error::Boolean(_) | Error::Import(_) => MeshError::new_err(e.to_string()),
        Error::Light(_) => LightError::new_err(e.to_string()),
        _ => BspError::new_err(e.to_string()),
    }
}

/// The last study scene a run made on this process, with its mesh: a
/// task that gets its own copy of the scene (as from Ray's object store)
/// finds the scene here instead of snapping the mesh again. Only the
/// last one is kept (a worker's memory holds one scene's), and only runs
/// (`_hours_run`, the distributed studies' tasks) use it.
static LAST_STUDY: Mutex<Option<(bsp_shadows::Mesh, Arc<sun::StudyScene>)>> = Mutex::new(None);

/// How many study scenes runs have made on this process (for the tests).
static STUDY_SCENES_MADE: std::sync::atomic::AtomicUsize = std::sync::atomic::AtomicUsize::new(0);

/// How many study scenes `_hours_run` has made on this process: one per
/// distinct scene, however many copies of it the tasks got.
#[pyfunction]
fn _study_scenes_made() -> usize {
    STUDY_SCENES_MADE.load(std::sync::atomic::Ordering::Relaxed)
}

/// The pool every call runs on, as `set_threads` set it; `None`:
/// rayon's global pool, one thread per CPU the process may use.
static POOL: Mutex<Option<Arc<rayon::ThreadPool>>> = Mutex::new(None);

/// `work` without the GIL, on the module's pool.
fn run<T: Send>(py: Python<'_>, work: impl FnOnce() -> T + Send) -> T {
    let pool = POOL.lock().expect("the pool's lock").clone();
    py.detach(|| match pool {
        Some(pool) => pool.install(work),
        None => work(),
    })
}

/// Sets the number of threads the package's work runs on; `None` or 0:
/// the CPUs the process may use. Results do not depend on it.
#[pyfunction]
#[pyo3(signature = (n=None))]
fn set_threads(n: Option<usize>) -> PyResult<()> {
    // (as the command line's --threads: thousands of threads took seconds
    // to start, tens of thousands hung)
    if let Some(n) = n
        && n > 1024
    {
        return Err(BspError::new_err(format!(
            "{n} threads: at most 1024 (0 or None: the CPUs this process may use)"
        )));
    }
    let pool = match n {
        None | Some(0) => None,
        Some(n) => Some(Arc::new(
            rayon::ThreadPoolBuilder::new()
                .num_threads(n)
                .build()
                .map_err(|e| BspError::new_err(e.to_string()))?,
        )),
    };
    *POOL.lock().expect("the pool's lock") = pool;
    Ok(())
}

/// The number of threads the package's work runs on.
#[pyfunction]
fn get_threads() -> usize {
    match &*POOL.lock().expect("the pool's lock") {
        Some(pool) => pool.current_num_threads(),
        None => rayon::current_num_threads(),
    }
}

/// `array` as a C-contiguous, aligned numpy array of `dtype` (a copy only
/// where it is not one already: arrays unpickled from out-of-band buffers
/// may be misaligned).
fn aligned<'py>(
    np: &Bound<'py, PyModule>,
    array: &Bound<'py, PyAny>,
    dtype: &str,
) -> PyResult<Bound<'py, PyAny>> {
    let kwargs = PyDict::new(np.py());
    kwargs.set_item("requirements", ["C", "A"])?;
    np.call_method("require", (array, dtype), Some(&kwargs))
}

/// `indices` (an array or a sequence) as vertex indices: integers, or
/// numbers that are whole (numpy's cast would cut `2.9` to `2` and take
/// `True` for `1`); `what` names them in the error.
fn whole_indices<'py>(
    np: &Bound<'py, PyModule>,
    indices: &Bound<'py, PyAny>,
    what: &str,
) -> PyResult<Bound<'py, PyAny>> {
    let a = np.call_method1("asarray", (indices,))?;
    let kind: String = a.getattr("dtype")?.getattr("kind")?.extract()?;
    let whole = match kind.as_str() {
        "i" | "u" => true,
        "f" => {
            let finite = np.call_method1("isfinite", (&a,))?;
            let floor = np.call_method1("floor", (&a,))?;
            np.call_method1("all", (finite,))?.extract::<bool>()?
                && np
                    .call_method1("array_equal", (&a, floor))?
                    .extract::<bool>()?
        }
        // (empty sequences are float; lists of lists of other lengths
        // are objects, which the caller takes face by face)
        "O" => return Ok(a),
        _ => false,
    };
    if !whole {
        return Err(MeshError::new_err(format!(
            "{what}: vertex indices must be whole numbers (given {} values)",
            a.getattr("dtype")?
        )));
    }
    Ok(a)
}

/// `array` as points, `(n, 3)` float64.
fn points<'py>(py: Python<'py>, array: &Bound<'py, PyAny>, what: &str) -> PyResult<Vec<DVec3>> {
    let out: Vec<DVec3> = rows(py, array, what, (&[3], "(n, 3)"), |flat, _| {
        Ok(flat
            .chunks_exact(3)
            .map(|p| DVec3::new(p[0], p[1], p[2]))
            .collect())
    })?;
    if let Some(i) = out.iter().position(|p| !p.is_finite()) {
        return Err(MeshError::new_err(format!(
            "{what}: row {i} is not finite ({}, {}, {})",
            out[i].x, out[i].y, out[i].z
        )));
    }
    Ok(out)
}

/// `read` of the numbers of a 2-D array of `float64` (converted if need
/// be, not copied where it is one), in C order, and its row width, which
/// must be one of `widths` (`shape` says which in errors).
fn rows<'py, T>(
    py: Python<'py>,
    array: &Bound<'py, PyAny>,
    what: &str,
    (widths, shape): (&[usize], &str),
    read: impl FnOnce(&[f64], usize) -> PyResult<T>,
) -> PyResult<T> {
    let np = py.import("numpy")?;
    let a = aligned(&np, array, "float64")?;
    let a: PyReadonlyArray2<'py, f64> = a
        .extract()
        .map_err(|_| MeshError::new_err(format!("{what}: an array of shape {shape} of numbers")))?;
    let dims = a.shape();
    if !widths.contains(&dims[1]) {
        return Err(MeshError::new_err(format!(
            "{what}: shape ({}, {}), not {shape}",
            dims[0], dims[1]
        )));
    }
    read(a.as_slice()?, dims[1])
}

/// Sensors from an array of shape `(n, 3)` (points) or `(n, 6)` (points
/// and their surfaces' normals, which must not be zero).
fn sensors<'py>(
    py: Python<'py>,
    array: &Bound<'py, PyAny>,
    what: &str,
) -> PyResult<Vec<bsp_shadows::sun::Sensor>> {
    use bsp_shadows::sun::Sensor;
    let shape = "(n, 3) (points) or (n, 6) (points and normals)";
    rows(py, array, what, (&[3, 6], shape), |flat, width| {
        (flat.chunks_exact(width).enumerate())
            .map(|(i, row)| {
                if let Some(x) = row.iter().find(|x| !x.is_finite()) {
                    return Err(MeshError::new_err(format!(
                        "{what}: row {i} is not finite ({x})"
                    )));
                }
                let normal = (row.len() == 6).then(|| DVec3::new(row[3], row[4], row[5]));
                Sensor::new(DVec3::new(row[0], row[1], row[2]), normal)
                    .ok_or_else(|| MeshError::new_err(format!("{what}: row {i}'s normal is zero")))
            })
            .collect()
    })
}

/// The first index of the whole-number array `a` (in C order) that
/// numpy's cast to `int64` would not keep (a `uint64` above `2^63 - 1`, a
/// float beyond `±2^63`): its flat position and its value as text.
fn beyond_int64(
    np: &Bound<'_, PyModule>,
    a: &Bound<'_, PyAny>,
) -> PyResult<Option<(usize, String)>> {
    let kind: String = a.getattr("dtype")?.getattr("kind")?.extract()?;
    let mask = match kind.as_str() {
        "u" => a.call_method1("__gt__", (i64::MAX,))?,
        "f" => np
            .call_method1("abs", (a,))?
            .call_method1("__ge__", (-(i64::MIN as f64),))?,
        _ => return Ok(None),
    };
    let flat = mask.call_method0("ravel")?;
    if !flat.call_method0("any")?.extract::<bool>()? {
        return Ok(None);
    }
    let at: usize = np.call_method1("argmax", (&flat,))?.extract()?;
    let value = a
        .call_method0("ravel")?
        .get_item(at)?
        .call_method0("item")?;
    Ok(Some((at, value.str()?.to_string())))
}

/// Faces from an `(m, k)` integer array or a sequence of polygons, checked.
fn faces_of(py: Python<'_>, faces: &Bound<'_, PyAny>, vertices: usize) -> PyResult<FlatFaces> {
    let np = py.import("numpy")?;
    let beyond = |face: usize, v: String| {
        MeshError::new_err(format!(
            "face {face} names vertex {v}, but the vertices are 0 to {}",
            vertices as i64 - 1
        ))
    };
    // every index in one array, and where each face starts
    let (flat, starts): (Vec<i64>, Vec<usize>) =
        if faces.hasattr("ndim")? && faces.getattr("ndim")?.extract::<usize>()? == 2 {
            let a = whole_indices(&np, faces, "faces")?;
            if let Some((at, v)) = beyond_int64(&np, &a)? {
                let k: usize = a.getattr("shape")?.get_item(1)?.extract()?;
                return Err(beyond(at / k.max(1), v));
            }
            let a = aligned(&np, &a, "int64")?;
            let a: PyReadonlyArray2<'_, i64> = a.extract()?;
            let (m, k) = (a.shape()[0], a.shape()[1]);
            (a.as_slice()?.to_vec(), (0..=m).map(|i| i * k).collect())
        } else {
            let (mut flat, mut starts) = (Vec::new(), vec![0]);
            for (i, face) in faces.try_iter()?.enumerate() {
                let face = whole_indices(&np, &face?, &format!("face {i}"))?;
                if let Some((_, v)) = beyond_int64(&np, &face)? {
                    return Err(beyond(i, v));
                }
                let a = np.call_method1("asarray", (&face, "int64")).map_err(|_| {
                    MeshError::new_err(format!("face {i}: a sequence of vertex indices"))
                })?;
                let v: Vec<i64> = a.call_method0("tolist")?.extract().map_err(|_| {
                    MeshError::new_err(format!("face {i}: a flat sequence of vertex indices"))
                })?;
                flat.extend(v);
                starts.push(flat.len());
            }
            (flat, starts)
        };
    let bad = |i: usize| -> Option<String> {
        let l = &flat[starts[i]..starts[i + 1]];
        if l.len() < 3 {
            return Some(format!("face {i} has {} vertices, fewer than 3", l.len()));
        }
        let v = *l.iter().find(|&&v| v < 0 || v as u64 >= vertices as u64)?;
        Some(format!(
            "face {i} names vertex {v}, but the vertices are 0 to {}",
            vertices as i64 - 1
        ))
    };
    run(py, || {
        use rayon::prelude::*;
        // (the first bad face, whatever the threads' order)
        match (0..starts.len() - 1)
            .into_par_iter()
            .find_first(|&i| bad(i).is_some())
        {
            Some(i) => Err(bad(i).expect("found bad")),
            None => Ok(flat.par_iter().map(|&v| v as u32).collect()),
        }
    })
    .map(|indices| FlatFaces { indices, starts })
    .map_err(MeshError::new_err)
}

/// Each face's group as an index into the distinct names, in order of
/// first use.
fn group_ids(per_face: Vec<String>) -> (Vec<u32>, Vec<String>) {
    let mut names: Vec<String> = Vec::new();
    let mut index: std::collections::HashMap<String, u32> = Default::default();
    let ids = per_face
        .into_iter()
        .map(|g| {
            *index.entry(g).or_insert_with_key(|g| {
                names.push(g.clone());
                names.len() as u32 - 1
            })
        })
        .collect();
    (ids, names)
}

/// Checked faces as given: every face's vertex indices in one array.
struct FlatFaces {
    indices: Vec<u32>,
    /// Face `i` is `indices[starts[i]..starts[i + 1]]`.
    starts: Vec<usize>,
}

/// A mesh as the package holds it: the arrays it was given, until a job
/// needs the library's mesh (made once, in parallel, without the GIL).
struct MeshData {
    given: Option<(Vec<DVec3>, FlatFaces)>,
    /// With the arrays, each face's group (an index into the names) and
    /// the names; `None`: one group, `default`.
    groups: Option<(Vec<u32>, Vec<String>)>,
    built: std::sync::OnceLock<bsp_shadows::Mesh>,
    /// The mesh snapped and imported for sun studies' runs, made by the
    /// first run that needs it (a worker's tasks share it).
    study: std::sync::OnceLock<Arc<sun::StudyScene>>,
}

impl MeshData {
    /// The library's mesh of the given arrays.
    fn build(
        positions: &[DVec3],
        faces: &FlatFaces,
        groups: Option<&(Vec<u32>, Vec<String>)>,
    ) -> bsp_shadows::Mesh {
        use rayon::prelude::*;
        let faces = (0..faces.starts.len() - 1)
            .into_par_iter()
            .map(|i| Face {
                vertices: faces.indices[faces.starts[i]..faces.starts[i + 1]].to_vec(),
                line: 0,
                group: groups.map_or(0, |g| g.0[i]),
            })
            .collect();
        bsp_shadows::Mesh {
            positions: positions.to_vec(),
            faces,
            groups: groups.map_or_else(|| vec!["default".to_string()], |g| g.1.clone()),
        }
    }
}

/// A polygon mesh: `Mesh(vertices, faces)` with vertices an `(n, 3)`
/// float64 array and faces an `(m, k)` integer array or a list of
/// polygons (vertex index lists, counter-clockwise seen from outside).
#[pyclass(module = "bsp_shadows", frozen)]
#[derive(Clone)]
struct Mesh {
    data: Arc<MeshData>,
}

impl Mesh {
    fn of(mesh: bsp_shadows::Mesh) -> Mesh {
        Mesh {
            data: Arc::new(MeshData {
                given: None,
                groups: None,
                built: mesh.into(),
                study: std::sync::OnceLock::new(),
            }),
        }
    }

    /// The mesh snapped and imported for sun studies' runs, made once
    /// for this object, or found as the process's last one if that is of
    /// an equal mesh ([`LAST_STUDY`]); call without the GIL.
    fn study_scene(&self) -> Result<Arc<sun::StudyScene>, Error> {
        if let Some(s) = self.data.study.get() {
            return Ok(s.clone());
        }
        let mesh = self.mesh();
        let last = LAST_STUDY.lock().expect("the last study's lock");
        let found = (last.as_ref())
            .filter(|(m, _)| m == mesh)
            .map(|(_, s)| s.clone());
        drop(last);
        let scene = match found {
            Some(s) => s,
            None => {
                let s = Arc::new(sun::StudyScene::new(mesh)?);
                STUDY_SCENES_MADE.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
                *LAST_STUDY.lock().expect("the last study's lock") =
                    Some((mesh.clone(), s.clone()));
                s
            }
        };
        Ok(self.data.study.get_or_init(|| scene).clone())
    }

    /// The library's mesh (made on first use; call without the GIL).
    fn mesh(&self) -> &bsp_shadows::Mesh {
        let d = &self.data;
        d.built.get_or_init(|| {
            let (positions, faces) = d.given.as_ref().expect("a mesh given or built");
            MeshData::build(positions, faces, d.groups.as_ref())
        })
    }

    /// A copy of the library's mesh, for a job that takes it (from the
    /// arrays where they are kept: no mesh is made twice).
    fn owned(&self) -> bsp_shadows::Mesh {
        match (self.data.built.get(), &self.data.given) {
            (Some(m), _) => m.clone(),
            (None, Some((positions, faces))) => {
                MeshData::build(positions, faces, self.data.groups.as_ref())
            }
            (None, None) => unreachable!("a mesh given or built"),
        }
    }

    fn positions(&self) -> &[DVec3] {
        match &self.data.given {
            Some((p, _)) => p,
            None => &self.mesh().positions,
        }
    }

    fn face_count(&self) -> usize {
        match &self.data.given {
            Some((_, f)) => f.starts.len() - 1,
            None => self.mesh().faces.len(),
        }
    }

    /// Face `i`'s group, an index into [`Mesh::group_names`].
    fn group_of(&self, i: usize) -> usize {
        match (&self.data.given, &self.data.groups) {
            (Some(_), Some((ids, _))) => ids[i] as usize,
            (Some(_), None) => 0,
            (None, _) => self.mesh().faces[i].group as usize,
        }
    }

    /// Face `i`'s vertices.
    fn face(&self, i: usize) -> &[u32] {
        match &self.data.given {
            Some((_, f)) => &f.indices[f.starts[i]..f.starts[i + 1]],
            None => &self.mesh().faces[i].vertices,
        }
    }
}

#[pymethods]
impl Mesh {
    /// `groups`: each face's group name (a sequence of `m` strings), or
    /// `None` for one group, `default`.
    #[new]
    #[pyo3(signature = (vertices, faces, groups=None))]
    fn new(
        py: Python<'_>,
        vertices: &Bound<'_, PyAny>,
        faces: &Bound<'_, PyAny>,
        groups: Option<Vec<String>>,
    ) -> PyResult<Mesh> {
        let positions = points(py, vertices, "vertices")?;
        let faces = faces_of(py, faces, positions.len())?;
        let m = faces.starts.len() - 1;
        let groups = match groups {
            Some(g) if g.len() != m => {
                return Err(MeshError::new_err(format!(
                    "{} group names for {m} faces: give one a face",
                    g.len()
                )));
            }
            Some(g) => Some(group_ids(g)),
            None => None,
        };
        Ok(Mesh {
            data: Arc::new(MeshData {
                given: Some((positions, faces)),
                groups,
                built: std::sync::OnceLock::new(),
                study: std::sync::OnceLock::new(),
            }),
        })
    }

    /// Each face's group name, `(m,)` (a list).
    #[getter]
    fn groups(&self) -> Vec<String> {
        let names = self.group_names();
        (0..self.face_count())
            .map(|i| names[self.group_of(i)].clone())
            .collect()
    }

    /// The groups' names, in order of first use.
    #[getter]
    fn group_names(&self) -> Vec<String> {
        match (&self.data.given, &self.data.groups) {
            (Some(_), Some((_, names))) => names.clone(),
            (Some(_), None) => vec!["default".to_string()],
            (None, _) => self.mesh().groups.clone(),
        }
    }

    /// Reads an OBJ, STL or CityJSON (.json) file.
    #[staticmethod]
    fn read(py: Python<'_>, path: std::path::PathBuf) -> PyResult<Mesh> {
        run(py, || bsp_shadows::read_mesh(&path))
            .map(Mesh::of)
            .map_err(to_py)
    }

    /// A built-in scene: `"room"` (the core paper's test room), `"chair"`,
    /// `"cube"`, `"bunny"` (the Stanford bunny on a ground) and
    /// `"bunny-11k"` to `"bunny-893k"` (the same refined), `"city"` and
    /// `"city-100k"` (a block of buildings on a tiled ground), as the CLI's
    /// `--scene` gives them.
    #[staticmethod]
    fn scene(name: &str) -> PyResult<Mesh> {
        shadow_scene::scene_named(name)
            .map(Mesh::of)
            .map_err(BspError::new_err)
    }

    /// Writes the mesh as OBJ or STL, by the extension.
    fn write(&self, py: Python<'_>, path: std::path::PathBuf) -> PyResult<()> {
        run(py, || bsp_shadows::write_mesh(&path, self.mesh())).map_err(to_py)
    }

    /// The vertex positions, `(n, 3)` float64 (a copy).
    #[getter]
    fn vertices<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray2<f64>>> {
        let positions = self.positions();
        let flat: Vec<f64> = positions.iter().flat_map(|p| p.to_array()).collect();
        flat.into_pyarray(py).reshape([positions.len(), 3])
    }

    /// The faces: an `(m, k)` int64 array when every face has `k`
    /// vertices, else a list of 1-D int64 arrays.
    #[getter]
    fn faces<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        let m = self.face_count();
        let k = if m == 0 { 3 } else { self.face(0).len() };
        if (0..m).all(|i| self.face(i).len() == k) {
            let flat: Vec<i64> = (0..m)
                .flat_map(|i| self.face(i).iter().map(|&v| i64::from(v)))
                .collect();
            return Ok(flat.into_pyarray(py).reshape([m, k])?.into_any());
        }
        let list = PyList::empty(py);
        for i in 0..m {
            let v: Vec<i64> = self.face(i).iter().map(|&v| i64::from(v)).collect();
            list.append(v.into_pyarray(py))?;
        }
        Ok(list.into_any())
    }

    /// The volume enclosed, exact for the `f64` positions and rounded once.
    fn volume(&self, py: Python<'_>) -> f64 {
        run(py, || bsp_shadows::volume(self.mesh()))
    }

    /// Whether every edge is met by exactly two faces in opposite
    /// directions (a closed, oriented surface).
    fn is_closed(&self, py: Python<'_>) -> bool {
        run(py, || self.mesh().is_closed_oriented())
    }

    /// The mesh moved by `offset` (three numbers).
    fn translated(&self, py: Python<'_>, offset: [f64; 3]) -> Mesh {
        let by = DVec3::from_array(offset);
        Mesh::of(run(py, || bsp_shadows::translated(self.mesh(), by)))
    }

    /// A `trimesh.Trimesh` of the same vertices and faces (polygons are
    /// fanned), without trimesh's processing.
    fn to_trimesh<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        let trimesh = py.import("trimesh")?;
        let flat: Vec<i64> = (0..self.face_count())
            .map(|i| self.face(i))
            .flat_map(|f| (1..f.len() - 1).flat_map(move |k| [f[0], f[k], f[k + 1]].map(i64::from)))
            .collect();
        let n = flat.len() / 3;
        let faces = flat.into_pyarray(py).reshape([n, 3])?;
        let kwargs = PyDict::new(py);
        kwargs.set_item("process", false)?;
        trimesh
            .getattr("Trimesh")?
            .call((self.vertices(py)?, faces), Some(&kwargs))
    }

    /// The mesh of a `trimesh.Trimesh` (its vertices and faces).
    #[staticmethod]
    fn from_trimesh(py: Python<'_>, mesh: &Bound<'_, PyAny>) -> PyResult<Mesh> {
        Mesh::new(
            py,
            &mesh.getattr("vertices")?,
            &mesh.getattr("faces")?,
            None,
        )
    }

    fn __or__(&self, py: Python<'_>, other: &Mesh) -> PyResult<Mesh> {
        boolean(py, self, other, BoolOp::Union)
    }

    fn __and__(&self, py: Python<'_>, other: &Mesh) -> PyResult<Mesh> {
        boolean(py, self, other, BoolOp::Intersection)
    }

    fn __sub__(&self, py: Python<'_>, other: &Mesh) -> PyResult<Mesh> {
        boolean(py, self, other, BoolOp::Difference)
    }

    fn __repr__(&self) -> String {
        format!(
            "Mesh(vertices={}, faces={})",
            self.positions().len(),
            self.face_count()
        )
    }

    /// Pickled as flat arrays: the vertices, every face's vertex indices
    /// in one array and where each face starts, each face's group and the
    /// groups' names. Arrays pickle (and Dask and Ray move them) as
    /// buffers, with no Python object a face (a list of 100k faces took
    /// seconds to scatter to a cluster).
    #[allow(clippy::type_complexity)] // (the arrays, named above)
    fn __reduce__<'py>(
        slf: &Bound<'py, Self>,
    ) -> Reduced<
        'py,
        (
            Bound<'py, PyAny>,
            Bound<'py, PyArray1<u32>>,
            Bound<'py, PyArray1<u64>>,
            Bound<'py, PyArray1<u32>>,
            Vec<String>,
        ),
    > {
        let py = slf.py();
        let me = slf.get();
        let m = me.face_count();
        let (mut indices, mut starts) = (Vec::new(), vec![0u64]);
        for i in 0..m {
            indices.extend_from_slice(me.face(i));
            starts.push(indices.len() as u64);
        }
        let groups: Vec<u32> = (0..m).map(|i| me.group_of(i) as u32).collect();
        let f = py.import("bsp_shadows._native")?.getattr("_mesh_of_flat")?;
        Ok((
            f,
            (
                me.vertices(py)?.into_any(),
                indices.into_pyarray(py),
                starts.into_pyarray(py),
                groups.into_pyarray(py),
                me.group_names(),
            ),
        ))
    }
}

/// A mesh from [`Mesh::__reduce__`]'s flat arrays, checked as
/// `Mesh(...)` checks its arguments.
#[pyfunction]
fn _mesh_of_flat(
    py: Python<'_>,
    vertices: &Bound<'_, PyAny>,
    indices: PyReadonlyArray1<'_, u32>,
    starts: PyReadonlyArray1<'_, u64>,
    groups: PyReadonlyArray1<'_, u32>,
    names: Vec<String>,
) -> PyResult<Mesh> {
    let positions = points(py, vertices, "vertices")?;
    let indices = indices.as_array().to_vec();
    let groups = groups.as_array().to_vec();
    let starts: Vec<usize> = starts.as_array().iter().map(|&s| s as usize).collect();
    let m = starts.len().saturating_sub(1);
    let ends = starts.first() == Some(&0) && starts.last() == Some(&indices.len());
    if !ends || !starts.is_sorted() || groups.len() != m {
        return Err(MeshError::new_err(
            "a pickled mesh's arrays do not fit together",
        ));
    }
    if let Some(i) = (0..m).find(|&i| starts[i + 1] - starts[i] < 3) {
        return Err(MeshError::new_err(format!(
            "face {i} has fewer than 3 vertices"
        )));
    }
    if let Some(&v) = indices.iter().find(|&&v| v as usize >= positions.len()) {
        return Err(MeshError::new_err(format!(
            "a face names vertex {v} of {}",
            positions.len()
        )));
    }
    if groups.iter().any(|&g| g as usize >= names.len()) {
        return Err(MeshError::new_err("a face's group is not among the names"));
    }
    Ok(Mesh {
        data: Arc::new(MeshData {
            given: Some((positions, FlatFaces { indices, starts })),
            groups: Some((groups, names)),
            built: std::sync::OnceLock::new(),
            study: std::sync::OnceLock::new(),
        }),
    })
}

fn boolean(py: Python<'_>, a: &Mesh, b: &Mesh, op: BoolOp) -> PyResult<Mesh> {
    run(py, || bsp_shadows::boolean_of(a.owned(), b.owned(), op))
        .map(Mesh::of)
        .map_err(to_py)
}

/// The exact union of two closed meshes (also `a | b`).
#[pyfunction]
fn union(py: Python<'_>, a: &Mesh, b: &Mesh) -> PyResult<Mesh> {
    boolean(py, a, b, BoolOp::Union)
}

/// The exact intersection of two closed meshes (also `a & b`).
#[pyfunction]
fn intersection(py: Python<'_>, a: &Mesh, b: &Mesh) -> PyResult<Mesh> {
    boolean(py, a, b, BoolOp::Intersection)
}

/// The exact difference `a − b` of two closed meshes (also `a - b`).
#[pyfunction]
fn difference(py: Python<'_>, a: &Mesh, b: &Mesh) -> PyResult<Mesh> {
    boolean(py, a, b, BoolOp::Difference)
}

/// A point light at `position`.
#[pyclass(module = "bsp_shadows", frozen)]
#[derive(Clone)]
struct PointLight {
    #[pyo3(get)]
    position: (f64, f64, f64),
}

#[pymethods]
impl PointLight {
    #[new]
    fn new(position: (f64, f64, f64)) -> PointLight {
        PointLight { position }
    }

    fn __repr__(&self) -> String {
        format!("PointLight({:?})", self.position)
    }

    fn __reduce__<'py>(slf: &Bound<'py, Self>) -> (Bound<'py, PyAny>, ((f64, f64, f64),)) {
        (slf.get_type().into_any(), (slf.get().position,))
    }
}

/// A sun: a light infinitely far in `direction` (from the scene toward it).
#[pyclass(module = "bsp_shadows", frozen)]
#[derive(Clone)]
struct Sun {
    #[pyo3(get)]
    direction: (f64, f64, f64),
}

#[pymethods]
impl Sun {
    #[new]
    fn new(direction: (f64, f64, f64)) -> Sun {
        Sun { direction }
    }

    fn __repr__(&self) -> String {
        format!("Sun({:?})", self.direction)
    }

    fn __reduce__<'py>(slf: &Bound<'py, Self>) -> (Bound<'py, PyAny>, ((f64, f64, f64),)) {
        (slf.get_type().into_any(), (slf.get().direction,))
    }
}

fn light_of(light: &Bound<'_, PyAny>, i: usize) -> PyResult<Light> {
    if let Ok(p) = light.cast::<PointLight>() {
        let (x, y, z) = p.get().position;
        Ok(Light::Point(DVec3::new(x, y, z)))
    } else if let Ok(s) = light.cast::<Sun>() {
        let (x, y, z) = s.get().direction;
        Ok(Light::Sun(DVec3::new(x, y, z)))
    } else {
        Err(LightError::new_err(format!(
            "light {i} is neither a PointLight nor a Sun"
        )))
    }
}

/// The lit and shadowed parts of every face for some lights.
#[pyclass(module = "bsp_shadows", frozen)]
struct Shadows {
    mesh: Mesh,
    lights: Vec<Py<PyAny>>,
    shadows: bsp_shadows::Shadows,
}

/// Shades every face of `mesh` for `lights` (at most 64 `PointLight` or
/// `Sun`): exact lit and shadowed fragments.
#[pyfunction]
fn shadows(py: Python<'_>, mesh: &Mesh, lights: &Bound<'_, PyAny>) -> PyResult<Shadows> {
    let given: Vec<Bound<'_, PyAny>> = lights.try_iter()?.collect::<PyResult<_>>()?;
    let specs: Vec<Light> = (given.iter().enumerate())
        .map(|(i, l)| light_of(l, i))
        .collect::<PyResult<_>>()?;
    let s = run(py, || bsp_shadows::shadows(mesh.mesh(), &specs)).map_err(to_py)?;
    // (the command line notes faces left out; a Python user saw zeros)
    let faces = mesh.mesh().faces.len();
    let none = (0..faces).filter(|&f| s.face_area(f) == 0.0).count();
    if none > 0 {
        let message = format!(
            "{none} of {faces} faces have no area on the grid the scene and its lights share, \
             and were left out (faces without area, or smaller than a step of a grid fitted \
             to a scene and lights that span a wide range)"
        );
        let category = py.get_type::<pyo3::exceptions::PyUserWarning>();
        PyErr::warn(py, &category, &std::ffi::CString::new(message)?, 1)?;
    }
    Ok(Shadows {
        mesh: mesh.clone(),
        lights: given.into_iter().map(Bound::unbind).collect(),
        shadows: s,
    })
}

#[pymethods]
impl Shadows {
    /// `(faces, lights)` float64: the area of each face each light reaches.
    #[getter]
    fn lit_area<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray2<f64>>> {
        let (faces, lights) = (self.mesh.face_count(), self.lights.len());
        let flat: Vec<f64> = (0..faces)
            .flat_map(|f| (0..lights).map(move |l| (f, l)))
            .map(|(f, l)| self.shadows.lit_area(f, l))
            .collect();
        flat.into_pyarray(py).reshape([faces, lights])
    }

    /// `(faces,)` float64: each face's area.
    #[getter]
    fn face_area<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        let faces = self.mesh.face_count();
        (0..faces)
            .map(|f| self.shadows.face_area(f))
            .collect::<Vec<_>>()
            .into_pyarray(py)
    }

    /// The share of the whole surface light `light` reaches.
    fn lit_fraction(&self, light: usize) -> PyResult<f64> {
        if light >= self.lights.len() {
            return Err(LightError::new_err(format!(
                "light {light} of {}",
                self.lights.len()
            )));
        }
        Ok(self.shadows.lit_fraction(light))
    }

    /// Every fragment as arrays: `face` (F,) int64; `lit` (F,) uint64,
    /// bit i set where light i reaches it; `rings` (F+1,) int64, fragment
    /// f's rings are `rings[f]:rings[f+1]` (outer first, then holes);
    /// `ring_points` (R+1,) int64, ring r's points are
    /// `points[ring_points[r]:ring_points[r+1]]`; `points` (P, 3) float64.
    fn fragments<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let (mut face, mut lit, mut rings, mut packed) =
            (Vec::new(), Vec::new(), vec![0i64], Rings::default());
        for f in self.shadows.fragments() {
            face.push(f.face as i64);
            lit.push(f.lit);
            f.rings.iter().for_each(|r| packed.push(r));
            rings.push(packed.count() as i64);
        }
        let d = PyDict::new(py);
        d.set_item("face", face.into_pyarray(py))?;
        d.set_item("lit", lit.into_pyarray(py))?;
        d.set_item("rings", rings.into_pyarray(py))?;
        packed.put(&d)?;
        Ok(d)
    }

    /// Writes the fragments as JSON or OBJ, by the extension.
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
            "Shadows(faces={}, lights={})",
            self.mesh.face_count(),
            self.lights.len()
        )
    }

    /// Pickled as its mesh and lights; unpickling shades again (the same
    /// bits: the result is a function of them).
    fn __reduce__<'py>(slf: &Bound<'py, Self>) -> Reduced<'py, (Mesh, Bound<'py, PyList>)> {
        remade(slf.py(), "shadows", &slf.get().mesh, &slf.get().lights)
    }
}

/// The directions toward the suns of a study, `(s, 3)`: on each date, the
/// midpoints of the day's `step_minutes` intervals with the sun above the
/// horizon.
#[pyfunction]
#[pyo3(signature = (lat, lon, dates, step_minutes=10.0, utc_offset=0.0, north=0.0, up="z", height=0.0))]
#[allow(clippy::too_many_arguments)] // (Python keywords, each with a default)
fn study_suns<'py>(
    py: Python<'py>,
    lat: f64,
    lon: f64,
    dates: &Bound<'py, PyAny>,
    step_minutes: f64,
    utc_offset: f64,
    north: f64,
    up: &str,
    height: f64,
) -> PyResult<Bound<'py, PyArray2<f64>>> {
    let (site, days) = site_and_days(lat, lon, dates, north, up, height)?;
    let suns = bsp_shadows::sun::study_suns(&site, &days, step_minutes, utc_offset)
        .map_err(|e| BspError::new_err(e.to_string()))?;
    let flat: Vec<f64> = suns.iter().flat_map(|s| s.direction.to_array()).collect();
    flat.into_pyarray(py).reshape([suns.len(), 3])
}

/// The site of a study and its days, from Python's arguments.
fn site_and_days(
    lat: f64,
    lon: f64,
    dates: &Bound<'_, PyAny>,
    north: f64,
    up: &str,
    height: f64,
) -> PyResult<(SunSite, Vec<sun::NaiveDate>)> {
    let up: Up = up.parse().map_err(BspError::new_err)?;
    let mut days = Vec::new();
    for d in dates.try_iter()? {
        let text = d?.str()?.to_string();
        // (a datetime's text begins with its date)
        let date = text.get(..10).unwrap_or(&text);
        let day = sun::parse_date(date).map_err(|e| BspError::new_err(e.to_string()))?;
        days.push(day);
    }
    let site = SunSite {
        height,
        ..SunSite::new(lat, lon).with_axes(north, up)
    };
    Ok((site, days))
}

/// Each sensor's sun-on intervals on each day, in closed form (no time
/// sampling: `bsp_shadows::sun::sensor_intervals_facing`): per sensor,
/// per day, an array of shape (n, 2) of hours of the day's clock. The
/// sensors are points `(p, 3)`, or points with their surfaces' normals
/// `(p, 6)` (the sun counted only in front of the surface).
#[pyfunction]
#[pyo3(signature = (scene, points, lat, lon, dates, utc_offset=0.0, north=0.0, up="z", height=0.0))]
#[allow(clippy::too_many_arguments)] // (Python keywords, each with a default)
fn sensor_intervals<'py>(
    py: Python<'py>,
    scene: &Mesh,
    points: &Bound<'py, PyAny>,
    lat: f64,
    lon: f64,
    dates: &Bound<'py, PyAny>,
    utc_offset: f64,
    north: f64,
    up: &str,
    height: f64,
) -> PyResult<Vec<Vec<Bound<'py, PyArray2<f64>>>>> {
    let (site, days) = site_and_days(lat, lon, dates, north, up, height)?;
    let at = crate::sensors(py, points, "points")?;
    let paths =
        sun::day_paths(&site, &days, utc_offset).map_err(|e| BspError::new_err(e.to_string()))?;
    let on = run(py, || {
        sun::sensor_intervals_facing(scene.mesh(), &at, &paths)
    });
    on.into_iter()
        .map(|days| {
            days.into_iter()
                .map(|iv| {
                    let flat: Vec<f64> = iv.iter().flat_map(|&(a, b)| [a, b]).collect();
                    flat.into_pyarray(py).reshape([iv.len(), 2])
                })
                .collect()
        })
        .collect()
}

/// A study's hours per face.
#[pyclass(module = "bsp_shadows", frozen)]
struct SunHours {
    mesh: Mesh,
    suns: Vec<DVec3>,
    step_hours: f64,
    /// The sun as a disc of this radius (degrees), if it was.
    sun_disc: Option<f64>,
    /// The tiles a side the study was cut into (1: not cut).
    tiles: usize,
    hours: Vec<bsp_shadows::sun::FaceHours>,
}

impl SunHours {
    /// Whether the study kept the extremes (`min_hours`, `max_hours`).
    fn extremes(&self) -> bool {
        !self.hours.iter().any(|h| h.min_hours.is_nan())
    }
}

#[pymethods]
impl SunHours {
    /// `(faces,)`: each face's sun-hours (its points' mean).
    #[getter]
    fn per_face<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        self.hours
            .iter()
            .map(|h| h.sun_hours)
            .collect::<Vec<_>>()
            .into_pyarray(py)
    }

    /// `(faces,)`: the fewest hours a point of each face gets (NaN for a
    /// study run with `extremes=False`).
    #[getter]
    fn min_hours<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        self.hours
            .iter()
            .map(|h| h.min_hours)
            .collect::<Vec<_>>()
            .into_pyarray(py)
    }

    /// `(faces,)`: the most hours a point of each face gets (NaN without
    /// the extremes).
    #[getter]
    fn max_hours<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        self.hours
            .iter()
            .map(|h| h.max_hours)
            .collect::<Vec<_>>()
            .into_pyarray(py)
    }

    /// `(faces,)`: each face's area.
    #[getter]
    fn area<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        self.hours
            .iter()
            .map(|h| h.area)
            .collect::<Vec<_>>()
            .into_pyarray(py)
    }

    /// `(s, 3)`: the directions toward the study's suns.
    #[getter]
    fn suns<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray2<f64>>> {
        let flat: Vec<f64> = self.suns.iter().flat_map(|s| s.to_array()).collect();
        flat.into_pyarray(py).reshape([self.suns.len(), 3])
    }

    /// The hours each sun stands for.
    #[getter]
    fn step_hours(&self) -> f64 {
        self.step_hours
    }

    /// `(faces,)`: the area of each face whose points get at least `hours`.
    fn area_with_at_least<'py>(&self, py: Python<'py>, hours: f64) -> Bound<'py, PyArray1<f64>> {
        self.hours
            .iter()
            .map(|h| h.area_with_at_least(hours))
            .collect::<Vec<_>>()
            .into_pyarray(py)
    }

    /// `(p,)`: the exact sun-hours at each of `points` (`(p, 3)`), among
    /// the mesh's faces; or of sensors `(p, 6)`, each point with its
    /// surface's normal, counting only the suns in front of it.
    fn per_sensor<'py>(
        &self,
        py: Python<'py>,
        points: &Bound<'py, PyAny>,
    ) -> PyResult<Bound<'py, PyArray1<f64>>> {
        let at = crate::sensors(py, points, "points")?;
        let h = run(py, || {
            bsp_shadows::sun::sensor_hours_facing(
                self.mesh.mesh(),
                &at,
                &self.suns,
                self.step_hours,
            )
        });
        Ok(h.map_err(to_py)?.into_pyarray(py))
    }

    fn __repr__(&self) -> String {
        format!(
            "SunHours(faces={}, suns={})",
            self.hours.len(),
            self.suns.len()
        )
    }

    /// Pickled as the study that made it (the mesh, the suns, the step,
    /// the extremes, the disc and the tiles), made again on unpickling.
    #[allow(clippy::type_complexity)] // (the study's arguments, named above)
    fn __reduce__<'py>(
        slf: &Bound<'py, Self>,
    ) -> Reduced<
        'py,
        (
            Mesh,
            Bound<'py, PyArray2<f64>>,
            f64,
            bool,
            Option<f64>,
            usize,
        ),
    > {
        let py = slf.py();
        let me = slf.get();
        let f = py
            .import("bsp_shadows._native")?
            .getattr("_hours_of_suns")?;
        let extremes = me.extremes();
        let study = (me.mesh.clone(), me.suns(py)?, me.step_hours, extremes);
        Ok((
            f,
            (study.0, study.1, study.2, study.3, me.sun_disc, me.tiles),
        ))
    }
}

/// The sun-hours of every face of `mesh` under the suns `suns` (`(s, 3)`,
/// directions toward them), each standing for `step_hours`; with
/// `sun_disc` (degrees), each sun a disc of that radius (mean hours only);
/// with `tiles` > 1, the scene cut into `tiles × tiles` tiles, a run each.
#[pyfunction]
#[pyo3(signature = (mesh, suns, step_hours, extremes=true, sun_disc=None, tiles=1))]
fn _hours_of_suns(
    py: Python<'_>,
    mesh: &Mesh,
    suns: &Bound<'_, PyAny>,
    step_hours: f64,
    extremes: bool,
    sun_disc: Option<f64>,
    tiles: usize,
) -> PyResult<SunHours> {
    let suns = points(py, suns, "suns")?;
    if sun_disc.is_some() && tiles != 1 {
        return Err(BspError::new_err(
            "a study of the sun as a disc is not cut into tiles",
        ));
    }
    let hours = run(py, || match sun_disc {
        Some(r) => bsp_shadows::sun::sun_hours_disc(mesh.mesh(), &suns, step_hours, r),
        None => {
            bsp_shadows::sun::sun_hours_in_tiles(mesh.mesh(), &suns, step_hours, tiles, extremes)
        }
    })
    .map_err(to_py)?;
    Ok(SunHours {
        mesh: mesh.clone(),
        suns,
        step_hours,
        sun_disc,
        tiles,
        hours,
    })
}

/// The cells of the faces `faces` (a group's name, or face ids) of
/// `mesh` under the suns `suns` (`(s, 3)`), each standing for
/// `step_hours`: a dict of `face` (C,) int64, `hours` (C,), `area` (C,)
/// (holes taken out), `rings` (C+1,) int64 (cell c's rings are
/// `rings[c]:rings[c+1]`, its boundary first, then its holes),
/// `ring_points` (R+1,) int64 (ring r's corners are
/// `points[ring_points[r]:ring_points[r+1]]`) and `points` (P, 3).
#[pyfunction]
fn _region_hours<'py>(
    py: Python<'py>,
    mesh: &Mesh,
    suns: &Bound<'py, PyAny>,
    step_hours: f64,
    faces: &Bound<'py, PyAny>,
) -> PyResult<Bound<'py, PyDict>> {
    let suns = points(py, suns, "suns")?;
    let chosen = match faces.extract::<String>() {
        Ok(group) => sun::RegionFaces::Group(group),
        Err(_) => sun::RegionFaces::Ids(
            (faces.extract::<Vec<usize>>()?.into_iter())
                .map(|f| (f, f))
                .collect(),
        ),
    };
    let cells = run(py, || {
        let ids = chosen.faces(mesh.mesh())?;
        sun::region_hours(mesh.mesh(), &suns, step_hours, &ids)
    })
    .map_err(to_py)?;
    let (mut packed, mut rings) = (Rings::default(), vec![0i64]);
    for c in &cells {
        c.rings().for_each(|r| packed.push(r));
        rings.push(packed.count() as i64);
    }
    let d = PyDict::new(py);
    d.set_item("rings", rings.into_pyarray(py))?;
    let column = |f: fn(&sun::RegionCell) -> f64| cells.iter().map(f).collect::<Vec<_>>();
    let face: Vec<i64> = cells.iter().map(|c| c.face as i64).collect();
    d.set_item("face", face.into_pyarray(py))?;
    d.set_item("hours", column(|c| c.hours).into_pyarray(py))?;
    d.set_item("area", column(|c| c.area).into_pyarray(py))?;
    packed.put(&d)?;
    Ok(d)
}

/// One run of a study (at most 64 suns) as bytes: a task of the
/// distributed study; with `tile` (`(index, per_side)`), of that tile's
/// faces only.
#[pyfunction]
#[pyo3(signature = (mesh, suns, step_hours, extremes=true, tile=None))]
fn _hours_run<'py>(
    py: Python<'py>,
    mesh: &Mesh,
    suns: &Bound<'py, PyAny>,
    step_hours: f64,
    extremes: bool,
    tile: Option<(usize, usize)>,
) -> PyResult<Bound<'py, PyBytes>> {
    let suns = points(py, suns, "suns")?;
    if suns.len() > MAX_SUNS_A_RUN {
        return Err(LightError::new_err(format!(
            "{} suns in one run; at most {MAX_SUNS_A_RUN}",
            suns.len()
        )));
    }
    let bytes = run(py, || {
        // (the mesh snapped once for all the runs made on this process)
        let tile = tile.map(|(index, per_side)| sun::Tile { index, per_side });
        let scene = mesh.study_scene()?;
        HoursRun::on(&scene, mesh.mesh(), &suns, step_hours, extremes, tile).map(|r| r.to_bytes())
    })
    .map_err(to_py)?;
    Ok(PyBytes::new(py, &bytes))
}

/// The study's hours from its runs' bytes, folded in the order given
/// (`tiles`: the tiles a side its runs were cut into, for pickling).
#[pyfunction]
#[pyo3(signature = (mesh, runs, suns, step_hours, tiles=1))]
fn _fold_runs(
    py: Python<'_>,
    mesh: &Mesh,
    runs: Vec<Vec<u8>>,
    suns: &Bound<'_, PyAny>,
    step_hours: f64,
    tiles: usize,
) -> PyResult<SunHours> {
    let suns = points(py, suns, "suns")?;
    let faces = mesh.face_count();
    let parsed = run(py, || {
        (runs.iter().enumerate())
            .map(|(i, b)| match HoursRun::from_bytes(b) {
                Some(r) if r.faces() == faces => Ok(r),
                Some(r) => Err(format!(
                    "run {i} is of a mesh of {} faces, not {faces}",
                    r.faces()
                )),
                None => Err(format!("run {i} is not a run's bytes")),
            })
            .collect::<Result<Vec<_>, _>>()
    })
    .map_err(BspError::new_err)?;
    let hours = run(py, || HoursRun::fold(faces, parsed.into_iter().map(Ok))).map_err(to_py)?;
    Ok(SunHours {
        mesh: mesh.clone(),
        suns,
        step_hours,
        sun_disc: None,
        tiles,
        hours,
    })
}

/// The number of suns a run of a study takes, as one process cuts it
/// (`sun::SUNS_A_RUN`).
const MAX_SUNS_A_RUN: usize = sun::SUNS_A_RUN;

#[pymodule]
fn _native(m: &Bound<'_, PyModule>) -> PyResult<()> {
    let py = m.py();
    m.add("BspError", py.get_type::<BspError>())?;
    m.add("MeshError", py.get_type::<MeshError>())?;
    m.add("LightError", py.get_type::<LightError>())?;
    m.add("MAX_SUNS_A_RUN", MAX_SUNS_A_RUN)?;
    m.add_class::<Mesh>()?;
    m.add_class::<PointLight>()?;
    m.add_class::<Sun>()?;
    m.add_class::<Shadows>()?;
    m.add_class::<soft::AreaLight>()?;
    m.add_class::<soft::SunDisc>()?;
    m.add_class::<soft::SoftShadows>()?;
    m.add_class::<SunHours>()?;
    for f in [
        wrap_pyfunction!(union, m)?,
        wrap_pyfunction!(intersection, m)?,
        wrap_pyfunction!(difference, m)?,
        wrap_pyfunction!(shadows, m)?,
        wrap_pyfunction!(soft::soft_shadows, m)?,
        wrap_pyfunction!(study_suns, m)?,
        wrap_pyfunction!(sensor_intervals, m)?,
        wrap_pyfunction!(_hours_of_suns, m)?,
        wrap_pyfunction!(_hours_run, m)?,
        wrap_pyfunction!(_mesh_of_flat, m)?,
        wrap_pyfunction!(_study_scenes_made, m)?,
        wrap_pyfunction!(_region_hours, m)?,
        wrap_pyfunction!(_fold_runs, m)?,
        wrap_pyfunction!(set_threads, m)?,
        wrap_pyfunction!(get_threads, m)?,
    ] {
        m.add_function(f)?;
    }
    Ok(())
}
