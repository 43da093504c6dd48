//! Mesh Booleans by local BSPs in an adaptive octree (`bsp-csg`).
//!
//! * `octree_csg/union/sphere N`: a unit UV sphere of about N triangles (1k,
//!   10k, 100k) united with a copy rotated 5° about (1, 2, 3) and shifted by
//!   (0.3, 0.1, 0.05) — the inputs of `scripts/manifold_compare.py`. End to
//!   end from the meshes: snap to one grid and make both solids, the union,
//!   the output triangle mesh and its watertightness check.
//! * `octree_csg/union_planned/sphere N`: the same, as the CLI makes it:
//!   the union decided (`Solid::plan_owned`) and meshed straight from the
//!   two solids' faces (`Planned::into_watertight_mesh`), with no solid for
//!   the result.
//! * `octree_csg/snap/sphere N`: the first step of those alone: the grid
//!   fitted to both meshes, and both snapped to it as solids (faces,
//!   support planes and face index).
//! * `octree_csg/drill/N`: N successive subtractions of 1k-triangle spheres
//!   (radius 0.05, centred on the surface along a Fibonacci spiral) from a
//!   10k-triangle sphere, on snapped solids (the `drill` example runs the
//!   1000-tool case of the docs).
//! * `octree_csg/resolve/spheres N`: the sphere pair of `union` in one
//!   mesh (two shells that cross), snapped and resolved to where its
//!   winding number is positive (`Solid::resolved`, cell by cell), and
//!   meshed: what `shadow csg union TWO.obj` does; compare with
//!   `union/sphere N`, the same solid from two operands.

use bsp_core::BoolOp;
use bsp_csg::{MeshIn, Snapped, Solid, snap};
use bsp_fixtures::{drill_tools, joined, sphere_pair, uv_sphere};
use criterion::{BatchSize, BenchmarkId, Criterion, criterion_group, criterion_main};

/// Both meshes snapped to one grid, as solids (what a mesh boolean does
/// first).
fn snapped_pair(a: MeshIn<'_>, b: MeshIn<'_>) -> (Solid, Solid) {
    let Snapped { solids, .. } = snap(&[a, b]).unwrap();
    let [sa, sb]: [Solid; 2] = solids.try_into().expect("two solids");
    (sa, sb)
}

fn union(c: &mut Criterion) {
    let mut g = c.benchmark_group("octree_csg/union");
    g.sample_size(10);
    for n in [1_000, 10_000, 100_000] {
        let (va, vb, f) = sphere_pair(n);
        g.bench_with_input(BenchmarkId::new("sphere", f.len()), &(), |bch, _| {
            bch.iter(|| {
                let r = bsp_csg::mesh_boolean(
                    &MeshIn::new(&va, &f),
                    &MeshIn::new(&vb, &f),
                    BoolOp::Union,
                )
                .unwrap();
                r.mesh.triangles.len()
            })
        });
    }
    g.finish();
    let mut g = c.benchmark_group("octree_csg/union_planned");
    g.sample_size(10);
    for n in [1_000, 10_000, 100_000] {
        let (va, vb, f) = sphere_pair(n);
        let (a, b) = (MeshIn::new(&va, &f), MeshIn::new(&vb, &f));
        g.bench_with_input(BenchmarkId::new("sphere", f.len()), &(), |bch, _| {
            bch.iter(|| {
                let (sa, sb) = snapped_pair(a, b);
                let planned = sa.plan_owned(sb, BoolOp::Union).unwrap();
                planned.into_watertight_mesh().unwrap().triangles.len()
            })
        });
    }
    g.finish();
    let mut g = c.benchmark_group("octree_csg/snap");
    g.sample_size(10);
    for n in [10_000, 100_000] {
        let (va, vb, f) = sphere_pair(n);
        let (a, b) = (MeshIn::new(&va, &f), MeshIn::new(&vb, &f));
        g.bench_with_input(BenchmarkId::new("sphere", f.len()), &(), |bch, _| {
            bch.iter(|| {
                let (sa, sb) = snapped_pair(a, b);
                sa.len() + sb.len()
            })
        });
    }
    g.finish();
}

fn resolve(c: &mut Criterion) {
    let mut g = c.benchmark_group("octree_csg/resolve");
    g.sample_size(10);
    for n in [10_000, 100_000] {
        let (va, vb, f) = sphere_pair(n);
        let (positions, faces) = joined(&[(&va, &f), (&vb, &f)]);
        g.bench_with_input(BenchmarkId::new("spheres", f.len()), &(), |bch, _| {
            bch.iter(|| {
                let r = bsp_csg::mesh_sequence(&MeshIn::new(&positions, &faces), &[]).unwrap();
                r.mesh.triangles.len()
            })
        });
    }
    g.finish();
}

fn drill(c: &mut Criterion) {
    let mut g = c.benchmark_group("octree_csg/drill");
    g.sample_size(10);
    let (pv, pf) = uv_sphere(10_000);
    let tools = 20;
    let (placed, tf) = drill_tools(tools, 1_000);
    let mut meshes = vec![MeshIn::new(&pv, &pf)];
    meshes.extend(placed.iter().map(|v| MeshIn::new(v, &tf)));
    let Snapped { solids, .. } = snap(&meshes).unwrap();
    g.bench_with_input(BenchmarkId::from_parameter(tools), &(), |bch, _| {
        bch.iter_batched(
            || solids[0].clone(),
            |mut part| {
                for tool in &solids[1..] {
                    part.apply(tool, BoolOp::Difference).unwrap();
                }
                part.len()
            },
            BatchSize::LargeInput,
        )
    });
    g.finish();
}

criterion_group!(benches, union, resolve, drill);
criterion_main!(benches);
