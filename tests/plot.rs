//! Every kind of plot renders to a non-empty SVG file, and bad input is a typed error.
#![cfg(feature = "plot")]

use nonsmooth_modes::plot::{
    backbone_panel, histories_panel, plot_backbone, plot_histories, plot_snapshots,
    plot_space_time, plot_xy, render_svg, space_time_panel, Annotation, Figure, LegendPosition,
    LinePanel, MapPanel, Panel, PlacedBar, Placement, PlotError, Series, SpaceTimeField,
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

/// The `x` and `y` of the `<text>` element whose content is `content`.
fn text_position(svg: &str, content: &str) -> (f64, f64) {
    let end = svg
        .find(&format!(">{content}</text>"))
        .unwrap_or_else(|| panic!("no text {content:?}"));
    let start = svg[..end].rfind("<text ").unwrap();
    let tag = &svg[start..end];
    let attr = |name: &str| -> f64 {
        let key = format!(" {name}=\"");
        let at = tag.find(&key).unwrap() + key.len();
        let len = tag[at..].find('"').unwrap();
        tag[at..at + len].parse().unwrap()
    };
    (attr("x"), attr("y"))
}

/// A panel of one labelled series on `points` (the canvas is 640 x 440).
fn legend_panel(points: Vec<(f64, f64)>) -> Figure {
    let mut panel = LinePanel::new("", "x", "y");
    panel.x_range = Some((0.0, 1.0));
    panel.y_range = Some((0.0, 1.0));
    panel.series.push(Series::markers("the data", points));
    Figure::new("", 1, vec![panel.into()])
}

#[test]
fn the_automatic_legend_covers_no_data() {
    let dir = out_dir("legend");
    // Data in the upper left quarter only: the legend goes to the upper right.
    let path = dir.join("corner.svg");
    let cloud: Vec<(f64, f64)> = (0..=20)
        .flat_map(|i| (0..=20).map(move |j| (0.025 * i as f64, 0.5 + 0.025 * j as f64)))
        .collect();
    render_svg(&path, &legend_panel(cloud)).unwrap();
    let svg = std::fs::read_to_string(&path).unwrap();
    let (x, y) = text_position(&svg, "the data");
    assert!(x > 320.0 && y < 220.0, "legend at ({x}, {y})");
    // Data everywhere: the legend goes outside the plot, right of its frame.
    let path = dir.join("full.svg");
    let grid: Vec<(f64, f64)> = (0..=40)
        .flat_map(|i| (0..=40).map(move |j| (i as f64 / 40.0, j as f64 / 40.0)))
        .collect();
    render_svg(&path, &legend_panel(grid.clone())).unwrap();
    let svg = std::fs::read_to_string(&path).unwrap();
    let (x, _) = text_position(&svg, "the data");
    let rightmost_tick = text_position(&svg, "1").0;
    assert!(
        x > rightmost_tick,
        "legend at x = {x}, axis ends at {rightmost_tick}"
    );
    // Data everywhere and a label too long for a strip on the right: below the plot.
    let long = "a label long enough that a strip for it would take half the panel";
    let mut wide = legend_panel(grid);
    if let Panel::Lines(p) = &mut wide.panels[0] {
        p.series[0].label = long.into();
    }
    let path = dir.join("below.svg");
    render_svg(&path, &wide).unwrap();
    let svg = std::fs::read_to_string(&path).unwrap();
    let (_, y) = text_position(&svg, long);
    let axis_label = text_position(&svg, "x").1;
    assert!(
        y > axis_label,
        "legend at y = {y}, axis label at {axis_label}"
    );
    // A fixed position is kept, whatever it covers.
    let mut fixed = legend_panel(vec![(0.5, 0.5)]);
    if let Panel::Lines(p) = &mut fixed.panels[0] {
        p.legend = LegendPosition::LowerRight;
    }
    let path = dir.join("fixed.svg");
    render_svg(&path, &fixed).unwrap();
    let svg = std::fs::read_to_string(&path).unwrap();
    let (x, y) = text_position(&svg, "the data");
    assert!(x > 320.0 && y > 220.0, "legend at ({x}, {y})");
}

#[test]
fn point_labels_are_drawn_and_text_offsets_are_in_pixels() {
    let dir = out_dir("labels");
    let mut panel = backbone_panel("lettered", &[Series::markers("NSM1", exact_curve())], None);
    let p = exact_curve()[10];
    panel.annotations = vec![Annotation::new(p, "a"), Annotation::new(p, "b")];
    let path = dir.join("labels.svg");
    render_svg(&path, &Figure::new("Ω/ω₁", 1, vec![panel.into()])).unwrap();
    let svg = std::fs::read_to_string(&path).unwrap();
    let (a, b) = (text_position(&svg, "a"), text_position(&svg, "b"));
    assert!(a != b, "two labels of one point at the same place");
    // Every vertical text offset is baked into `y`: no `dy` in font-relative units.
    assert!(!svg.contains("dy="), "a text keeps a relative offset");
    assert!(svg.contains(">Ω/ω₁</text>"));
}
