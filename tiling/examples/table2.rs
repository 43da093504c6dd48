//! Liu & Wu's Table 2 on our room: the static scene at the paper's sizes
//! (255 and 345 static polygons: the room without some furniture), a
//! moving object of 6 faces (a cube) or the coordinate-axis object (51
//! faces; the paper's had 48), one point light, both strategies. Prints a
//! Markdown table of the means over the frames of each animation.
//!
//! ```sh
//! cargo run --release -p tiling --example table2 [FRAMES]
//! ```

use glam::DVec3;
use shadow_scene::Mesh;
use svbsp::{LightSpec, place_lights, shared_grid};
use tiling::{Dynamic, FrameStats, Motion, PipelineOptions, Strategy};

/// The room without the groups named.
fn room_without(groups: &[&str]) -> (Mesh, Mesh) {
    let (mut rest, axes) = shadow_scene::room()
        .split_off_group("axes")
        .expect("the room has its axis object");
    for g in groups {
        rest = rest.split_off_group(g).expect("a group of the room").0;
    }
    (rest, axes)
}

/// A cube of side 0.4 standing where the axis object's pedestal is.
fn cube() -> Mesh {
    let mut m = shadow_scene::scene("cube").expect("the unit cube");
    for p in &mut m.positions {
        *p = (*p - DVec3::new(0.5, 0.5, 0.0)) * 0.4 + DVec3::new(0.0, 0.0, 0.01);
    }
    m
}

struct Row {
    label: &'static str,
    statics: Mesh,
    moving: Mesh,
    motion: Motion,
}

fn mean(rows: &[FrameStats], f: impl Fn(&FrameStats) -> f64) -> f64 {
    rows.iter().map(&f).sum::<f64>() / rows.len() as f64
}

fn main() {
    let frames: u32 = std::env::args()
        .nth(1)
        .and_then(|a| a.parse().ok())
        .unwrap_or(24);
    let few = ["books", "plant", "flower", "decor"];
    let some = ["plant", "pot", "soil", "flower"];
    let spin = |m: &Mesh, axis: DVec3, deg: f64| {
        let (lo, hi) = m.bounds().expect("a moving object");
        Motion {
            axis,
            degrees: deg,
            centre: (lo + hi) * 0.5,
            step: DVec3::ZERO,
        }
    };
    let rows = {
        let (s1, axes) = room_without(&few);
        let (s2, _) = room_without(&some);
        let (s3, _) = room_without(&[]);
        let c = cube();
        vec![
            Row {
                label: "cube spinning",
                motion: spin(&c, DVec3::Z, 15.0),
                statics: s1.clone(),
                moving: c,
            },
            Row {
                label: "axes spinning",
                motion: spin(&axes, DVec3::Z, 15.0),
                statics: s1.clone(),
                moving: axes.clone(),
            },
            Row {
                label: "axes tumbling",
                motion: spin(&axes, DVec3::new(1.0, 1.0, 0.3), 15.0),
                statics: s1,
                moving: axes.clone(),
            },
            Row {
                label: "axes spinning",
                motion: spin(&axes, DVec3::Z, 15.0),
                statics: s2,
                moving: axes.clone(),
            },
            Row {
                label: "axes spinning (whole room)",
                motion: spin(&axes, DVec3::Z, 15.0),
                statics: s3,
                moving: axes,
            },
        ]
    };
    println!(
        "| motion | strategy | static polygons | dynamic polygons | dynamic after BSP | static \
         after BSP | static after shadow | dynamic shadow polygons | total drawn | tiling (ms) \
         | merge (ms) | dynamic shadows (ms) | frame (ms) |"
    );
    println!("|---|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|");
    for row in &rows {
        let statics = row.statics.face_loops();
        let moving = row.moving.face_loops();
        let mut pts = row.statics.positions.clone();
        for k in 0..frames {
            let m = row.motion.matrix(k);
            pts.extend(row.moving.positions.iter().map(|&p| m.transform_point3(p)));
        }
        let spec = [LightSpec::Point(shadow_scene::ROOM_LIGHT)];
        let grid = shared_grid(&pts, &spec).expect("a grid");
        let light = place_lights(&grid, &spec).expect("the light")[0].light;
        for strategy in [Strategy::Paper, Strategy::Fast] {
            let d = Dynamic::new(
                &statics,
                &moving,
                grid,
                &[light],
                PipelineOptions::default().with_strategy(strategy),
            )
            .expect("the pipeline");
            let stats: Vec<FrameStats> = (0..frames)
                .map(|k| d.frame(&row.motion.matrix(k)).expect("a frame").stats)
                .collect();
            let ms = |f: fn(&FrameStats) -> std::time::Duration| {
                mean(&stats, |s| f(s).as_secs_f64() * 1e3)
            };
            println!(
                "| {} | {:?} | {} | {} | {:.0} | {} | {} | {:.0} | {:.0} | {:.3} | {:.3} | {:.3} | \
                 {:.3} |",
                row.label,
                strategy,
                stats[0].static_polygons,
                stats[0].dynamic_polygons,
                mean(&stats, |s| s.dynamic_after_bsp as f64),
                stats[0].static_after_bsp,
                stats[0].static_after_shadow,
                mean(&stats, |s| s.dynamic_shadow_polygons as f64),
                mean(&stats, |s| s.total_drawn as f64),
                ms(|s| s.t_tiling),
                ms(|s| s.t_merge),
                ms(|s| s.t_dynamic_shadows),
                ms(|s| s.t_frame),
            );
        }
    }
}
