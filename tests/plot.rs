//! Every kind of plot renders to a non-empty SVG file, and bad input is a typed error.
#![cfg(feature = "plot")]

use nonsmooth_modes::plot::{
    backbone_panel, histories_panel, plot_backbone, plot_histories, plot_snapshots,
    plot_space_time, plot_xy, render_svg, space_time_panel, Figure, LinePanel, MapPanel, Panel,
    PlacedBar, Placement, PlotError, Series, SpaceTimeField,
};
use std::f64::consts::PI;
use std::path::PathBuf;

fn out_dir(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("nsm-plot-{}-{name}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

fn assert_svg(path: &std::path::Path) {
    let text = std::fs::read_to_string(path).unwrap();
    assert!(text.len() > 200, "{} is too short", path.display());
    let head = text.trim_start();
    assert!(
        head.starts_with("<svg") || head.starts_with("<?xml"),
        "{} does not look like SVG",
        path.display()
    );
    assert!(text.trim_end().ends_with("</svg>"));
}

fn exact_curve() -> Vec<(f64, f64)> {
    (0..91)
        .map(|i| {
            let t = 3.95 - 0.01 * i as f64;
            (4.0 / t, 8.0 / (PI * PI * (t - 3.0).powi(2)))
        })
        .collect()
}

fn field(length: f64, phase: f64) -> SpaceTimeField {
    let position: Vec<f64> = (0..21).map(|i| length * i as f64 / 20.0).collect();
    let time: Vec<f64> = (0..32).map(|k| 4.0 * k as f64 / 32.0).collect();
    let mut values = Vec::new();
    for t in &time {
        for x in &position {
            values.push(1e-3 * (PI * x / (2.0 * length)).sin() * (PI * t / 2.0 + phase).cos());
        }
    }
    SpaceTimeField {
        position,
        time,
        values,
    }
}

#[test]
fn backbone_plot_with_exact_curve() {
    let dir = out_dir("backbone");
    let exact = exact_curve();
    let mut computed: Vec<(f64, f64)> = exact
        .iter()
        .step_by(4)
        .map(|&(w, e)| (w, e * 1.02))
        .collect();
    computed[3].1 = f64::NAN; // an unconverged point leaves a gap
    let branches = [
        Series::markers("NSM1", computed),
        Series::markers("NSM2", vec![(3.0, 1.5), (3.1, 2.5), (3.2, 4.0)]),
    ];
    let path = dir.join("backbone.svg");
    plot_backbone(&path, "backbone", &branches, Some(&exact)).unwrap();
    assert_svg(&path);
}

#[test]
fn space_time_map() {
    let dir = out_dir("map");
    let path = dir.join("map.svg");
    plot_space_time(&path, "u(x, t)", &field(1.0, 0.0)).unwrap();
    assert_svg(&path);
}

#[test]
fn two_bar_snapshots() {
    let dir = out_dir("snap");
    let (one, two) = (field(1.0, 0.0), field(0.95, 0.3));
    let bars = [
        PlacedBar {
            name: "bar 1",
            field: &one,
            placement: Placement {
                origin: 0.0,
                mirrored: false,
            },
        },
        PlacedBar {
            name: "bar 2",
            field: &two,
            placement: Placement {
                origin: 1.95,
                mirrored: true,
            },
        },
    ];
    let path = dir.join("snap.svg");
    plot_snapshots(&path, "snapshots", &bars, 6, &[1.0]).unwrap();
    assert_svg(&path);
}

#[test]
fn histories_and_xy_and_composite() {
    let dir = out_dir("hist");
    let time: Vec<f64> = (0..200).map(|k| 3.5 * k as f64 / 200.0).collect();
    let u: Vec<f64> = time
        .iter()
        .map(|t| 1e-3 * (2.0 * PI * t / 3.5).cos())
        .collect();
    let r: Vec<f64> = time.iter().map(|t| 1e-4 * (6.0 * t).sin()).collect();
    let path = dir.join("hist.svg");
    plot_histories(&path, "end", &time, &[("u(1,t)", &u), ("r(t)", &r)]).unwrap();
    assert_svg(&path);

    let m: Vec<f64> = (1..=8).map(|k| (5 * k) as f64).collect();
    let err: Vec<(f64, f64)> = m.iter().map(|&m| (m, 0.3 / m)).collect();
    let path = dir.join("xy.svg");
    plot_xy(
        &path,
        "R(m)",
        "m",
        "R",
        true,
        true,
        &[
            Series::markers("R", err.clone()),
            Series::line("1/m", err).dashed(),
        ],
    )
    .unwrap();
    assert_svg(&path);

    let figure = Figure::new(
        "composite",
        2,
        vec![
            Panel::Lines(backbone_panel("b", &[], Some(&exact_curve()))),
            space_time_panel("f", &field(1.0, 0.0), "u").unwrap().into(),
            histories_panel("h", &time, &[("u", &u)]).unwrap().into(),
            Panel::Map(MapPanel {
                x: vec![0.0, 1.0, 2.0],
                y: vec![0.0, 1.0],
                values: vec![1.0, 2.0, f64::NAN, 4.0, 5.0, 6.0],
                overlay: vec![Series::line("", vec![(0.0, 0.0), (2.0, 1.0)])],
                ..Default::default()
            }),
        ],
    );
    let path = dir.join("composite.svg");
    render_svg(&path, &figure).unwrap();
    assert_svg(&path);
}

#[test]
fn bad_input_is_an_error_not_a_panic() {
    let dir = out_dir("bad");
    let short = SpaceTimeField {
        position: vec![0.0, 1.0],
        time: vec![0.0],
        values: vec![1.0],
    };
    assert!(matches!(
        plot_space_time(dir.join("a.svg"), "", &short),
        Err(PlotError::InvalidData { .. })
    ));
    let time = [0.0, 1.0];
    assert!(plot_histories(dir.join("b.svg"), "", &time, &[("u", &[1.0][..])]).is_err());
    assert!(render_svg(dir.join("c.svg"), &Figure::new("", 1, vec![])).is_err());
    let fixed = LinePanel {
        y_log: true,
        y_range: Some((0.0, 1.0)),
        ..Default::default()
    };
    assert!(render_svg(dir.join("d.svg"), &Figure::new("", 1, vec![fixed.into()])).is_err());
    // Nothing to draw is not an error: an empty frame.
    let path = dir.join("e.svg");
    plot_backbone(
        &path,
        "empty",
        &[Series::markers("none", vec![(f64::NAN, 1.0)])],
        None,
    )
    .unwrap();
    assert_svg(&path);
    // An unwritable path is a drawing error.
    let missing = dir.join("no-such-dir").join("f.svg");
    assert!(matches!(
        plot_backbone(&missing, "", &[], None),
        Err(PlotError::Draw(_))
    ));
}
