//! Exact helpers: the checks every driver shares.

#[allow(unused_imports)]
use super::*;

/// Filter and exact path must agree whenever the filter answers.
pub(crate) fn check_point_side(input: &dyn Debug, p: &Point, plane: &Plane) -> Side {
    let s = p.classify(plane);
    if let Point::Implicit(i) = p {
        let exact = i.classify_exact(plane);
        ensure!(
            input,
            exact == s,
            "Point::classify ({s:?}) differs from the exact path ({exact:?}) for {p:?} and {plane:?}"
        );
        if let Some(f) = i.classify_filtered(plane) {
            ensure!(
                input,
                f == exact,
                "the filter certified {f:?} but the exact side is {exact:?} for {p:?} and {plane:?}"
            );
        }
    }
    s
}

/// `true` if `p` lies in the closed polygon `poly` (exact).
pub(crate) fn inside_polygon(input: &dyn Debug, p: &Point, poly: &Polygon) -> Result<(), String> {
    if check_point_side(input, p, poly.support()) != Side::On {
        return Err("is off the support plane".into());
    }
    for (j, e) in poly.edge_planes().iter().enumerate() {
        if check_point_side(input, p, e) == Side::Front {
            return Err(format!("is outside edge plane {j}"));
        }
    }
    Ok(())
}

pub(crate) fn same_polygon(a: &Polygon, b: &Polygon) -> bool {
    a.tag() == b.tag()
        && a.support() == b.support()
        && a.edge_planes() == b.edge_planes()
        && a.len() == b.len()
        && a.vertices()
            .iter()
            .zip(b.vertices())
            .all(|(u, v)| u.same_point(v))
}

/// Twice the area vector of `verts` about `o`, and a bound on its
/// floating-point error per component (`m` bounds the coordinates).
pub(crate) fn area2(verts: &[[f64; 3]], o: [f64; 3], m: f64) -> ([f64; 3], f64) {
    let k = verts.len();
    let mut a = [0.0; 3];
    let mut err = 0.0;
    for i in 0..k {
        let p = [0, 1, 2].map(|c| verts[i][c] - o[c]);
        let q = [0, 1, 2].map(|c| verts[(i + 1) % k][c] - o[c]);
        let x = [
            p[1] * q[2] - p[2] * q[1],
            p[2] * q[0] - p[0] * q[2],
            p[0] * q[1] - p[1] * q[0],
        ];
        for c in 0..3 {
            a[c] += x[c];
        }
        let (np, nq) = (max_abs(p), max_abs(q));
        err += np * nq + m * (np + nq);
    }
    (a, err)
}

pub(crate) fn max_abs(v: [f64; 3]) -> f64 {
    v.iter().fold(0.0, |m, c| m.max(c.abs()))
}

/// The pieces cover `whole`: each lies inside it (exact), and their areas
/// add up to its area (in `f64`, with a rounding-error bound: the exact
/// containment is the real test, this one catches lost or doubled pieces).
pub(crate) fn check_cover(input: &dyn Debug, whole: &Polygon, pieces: &[&Polygon], what: &str) {
    for (i, p) in pieces.iter().enumerate() {
        ensure!(
            input,
            p.support() == whole.support(),
            "{what}: piece {i} has support {:?}, not the original's {:?}",
            p.support(),
            whole.support()
        );
        for (k, v) in p.vertices().iter().enumerate() {
            if let Err(e) = inside_polygon(input, v, whole) {
                fail(
                    input,
                    format_args!("{what}: vertex {k} of piece {i} ({v:?}) {e} of the original"),
                );
            }
        }
    }
    let wv = whole.vertices_f64();
    let o = wv[0];
    let pv: Vec<Vec<[f64; 3]>> = pieces.iter().map(|p| p.vertices_f64()).collect();
    let m = pv
        .iter()
        .flatten()
        .chain(&wv)
        .fold(0.0f64, |m, v| m.max(max_abs(*v)));
    let (aw, mut err) = area2(&wv, o, m);
    let mut sum = [0.0; 3];
    for v in &pv {
        let (a, e) = area2(v, o, m);
        err += e;
        for c in 0..3 {
            sum[c] += a[c];
        }
    }
    let tol = err * 2f64.powi(-40);
    for c in 0..3 {
        let close = (sum[c] - aw[c]).abs() <= tol;
        ensure!(
            input,
            close,
            "{what}: the pieces' area vector {sum:?} differs from the original's {aw:?} \
             by more than the rounding bound {tol:e}"
        );
    }
}
