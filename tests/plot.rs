//! Tests of the hand-drawn anchor plot (`sagcal::plot`) and of writing figures as SVG or PNG.

use std::collections::HashMap;
use std::path::Path;

use sagcal::plot::residuals::{residual_plot_svg, ResidualPlot, ResidualSeries};
use sagcal::plot::{anchor_plot_svg, svg_to_png, write_figure, AnchorPlot, AnchorPlotEntry, PNG_SCALE};

// ---------------------------------------------------------------------------
// A minimal XML reader: checks well-formedness (balanced, properly nested tags,
// quoted attributes, valid entities) and returns the elements with their
// attributes and the attributes of the enclosing `<g class="panel">`.

#[derive(Debug, Clone)]
struct Elem {
    name: String,
    attrs: HashMap<String, String>,
    panel: Option<HashMap<String, String>>,
}

fn check_entities(text: &str, what: &str) {
    let mut rest = text;
    while let Some(i) = rest.find('&') {
        let tail = &rest[i + 1..];
        let end = tail
            .find(';')
            .unwrap_or_else(|| panic!("unterminated entity in {what}: {text:?}"));
        let ent = &tail[..end];
        let ok = matches!(ent, "amp" | "lt" | "gt" | "quot" | "apos")
            || (ent.starts_with("#x") && ent.len() > 2 && u32::from_str_radix(&ent[2..], 16).is_ok())
            || (ent.starts_with('#') && ent.len() > 1 && ent[1..].parse::<u32>().is_ok());
        assert!(ok, "bad entity &{ent}; in {what}");
        rest = &tail[end + 1..];
    }
    assert!(!text.contains('<'), "raw '<' in {what}: {text:?}");
}

fn parse_attrs(body: &str) -> HashMap<String, String> {
    let mut attrs = HashMap::new();
    let mut rest = body.trim();
    while !rest.is_empty() {
        let eq = rest
            .find('=')
            .unwrap_or_else(|| panic!("attribute without value in {body:?}"));
        let key = rest[..eq].trim().to_owned();
        assert!(
            !key.is_empty() && key.chars().all(|c| c.is_ascii_alphanumeric() || "-_:".contains(c)),
            "bad attribute name {key:?} in {body:?}"
        );
        let after = rest[eq + 1..].trim_start();
        let quote = after.chars().next().expect("attribute value");
        assert!(quote == '"' || quote == '\'', "unquoted attribute {key} in {body:?}");
        let close = after[1..]
            .find(quote)
            .unwrap_or_else(|| panic!("unterminated attribute {key}"));
        let value = &after[1..1 + close];
        check_entities(value, "attribute value");
        assert!(
            attrs.insert(key.clone(), value.to_owned()).is_none(),
            "duplicate attribute {key}"
        );
        rest = after[close + 2..].trim_start();
    }
    attrs
}

/// Parse `svg`, panicking on anything that is not well-formed.
fn parse_svg(svg: &str) -> Vec<Elem> {
    let mut out = Vec::new();
    // Stack of (element name, is panel group, panel attributes).
    let mut stack: Vec<(String, Option<HashMap<String, String>>)> = Vec::new();
    let mut roots = 0;
    let mut rest = svg;
    loop {
        let Some(lt) = rest.find('<') else {
            check_entities(rest, "trailing text");
            assert!(rest.trim().is_empty(), "text after the root element");
            break;
        };
        let text = &rest[..lt];
        check_entities(text, "text");
        assert!(
            !stack.is_empty() || text.trim().is_empty(),
            "text outside the root element: {text:?}"
        );
        rest = &rest[lt..];
        if let Some(r) = rest.strip_prefix("<?") {
            let end = r.find("?>").expect("unterminated processing instruction");
            assert!(stack.is_empty() && roots == 0, "prolog inside the document");
            rest = &r[end + 2..];
            continue;
        }
        if let Some(r) = rest.strip_prefix("<!--") {
            let end = r.find("-->").expect("unterminated comment");
            rest = &r[end + 3..];
            continue;
        }
        let gt = rest.find('>').expect("unterminated tag");
        let tag = &rest[1..gt];
        rest = &rest[gt + 1..];
        if let Some(name) = tag.strip_prefix('/') {
            let (open, _) = stack
                .pop()
                .unwrap_or_else(|| panic!("closing </{name}> without opening"));
            assert_eq!(open, name.trim(), "mismatched closing tag");
            continue;
        }
        let self_closing = tag.ends_with('/');
        let tag = tag.trim_end_matches('/');
        let name_end = tag.find(char::is_whitespace).unwrap_or(tag.len());
        let name = tag[..name_end].to_owned();
        assert!(
            !name.is_empty() && name.chars().all(|c| c.is_ascii_alphanumeric() || c == ':'),
            "bad element name {name:?}"
        );
        let attrs = parse_attrs(&tag[name_end..]);
        if stack.is_empty() {
            roots += 1;
            assert_eq!(roots, 1, "more than one root element");
            assert_eq!(name, "svg");
        }
        let enclosing_panel = stack.iter().rev().find_map(|(_, p)| p.clone());
        out.push(Elem {
            name: name.clone(),
            attrs: attrs.clone(),
            panel: enclosing_panel,
        });
        if !self_closing {
            let is_panel = name == "g" && attrs.get("class").map(String::as_str) == Some("panel");
            stack.push((name, is_panel.then_some(attrs)));
        }
    }
    assert!(stack.is_empty(), "unclosed elements: {stack:?}");
    assert_eq!(roots, 1, "no root element");
    out
}

fn assert_well_formed(svg: &str) -> Vec<Elem> {
    assert!(svg.starts_with("<?xml"));
    assert_eq!(svg.matches("<svg").count(), 1);
    assert_eq!(svg.matches("</svg>").count(), 1);
    assert_eq!(
        svg.matches("<g ").count() + svg.matches("<g>").count(),
        svg.matches("</g>").count()
    );
    for bad in ["NaN", "inf", "Infinity"] {
        assert!(!svg.contains(bad), "output contains {bad}");
    }
    parse_svg(svg)
}

fn num(s: &str) -> f64 {
    s.trim().parse().unwrap_or_else(|_| panic!("not a number: {s:?}"))
}

fn nums(s: &str) -> Vec<f64> {
    s.split(|c: char| c.is_whitespace() || c == ',')
        .filter(|t| !t.is_empty())
        .map(num)
        .collect()
}

/// The ellipses with sigma `k` of `view` ("xy" or "xz"), with their panel's attributes.
fn ellipses<'a>(elems: &'a [Elem], view: &str, k: u32) -> Vec<&'a Elem> {
    elems
        .iter()
        .filter(|e| e.name == "ellipse" && e.attrs.get("data-sigma").map(String::as_str) == Some(&k.to_string()))
        .filter(|e| e.panel.as_ref().and_then(|p| p.get("data-view")).map(String::as_str) == Some(view))
        .collect()
}

/// Closed form: 1-sigma semi-axes and major-axis angle [deg] of [[a, b], [b, d]].
fn closed_form(a: f64, b: f64, d: f64) -> (f64, f64, f64) {
    let m = 0.5 * (a + d);
    let h = (0.5 * (a - d)).hypot(b);
    (
        (m + h).sqrt(),
        (m - h).sqrt(),
        0.5 * (2.0 * b).atan2(a - d).to_degrees(),
    )
}

// ---------------------------------------------------------------------------
// Example data.

fn cov(s: [f64; 3], rho_xy: f64, rho_xz: f64, rho_yz: f64) -> [[f64; 3]; 3] {
    [
        [s[0] * s[0], rho_xy * s[0] * s[1], rho_xz * s[0] * s[2]],
        [rho_xy * s[0] * s[1], s[1] * s[1], rho_yz * s[1] * s[2]],
        [rho_xz * s[0] * s[2], rho_yz * s[1] * s[2], s[2] * s[2]],
    ]
}

fn add(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [a[0] + b[0], a[1] + b[1], a[2] + b[2]]
}

/// Offset of length `len` along `dir`.
fn along(dir: [f64; 3], len: f64) -> [f64; 3] {
    let n = (dir[0] * dir[0] + dir[1] * dir[1] + dir[2] * dir[2]).sqrt();
    [dir[0] * len / n, dir[1] * len / n, dir[2] * len / n]
}

fn example_plot() -> AnchorPlot {
    let truth = [
        [-125.0, -110.0, 48.0],
        [125.0, -110.0, 48.0],
        [125.0, 110.0, 48.0],
        [-125.0, 110.0, 48.0],
    ];
    let est_off = [
        [0.21, -0.14, 0.18],
        [-0.33, 0.12, -0.25],
        [0.18, 0.36, 0.31],
        [-0.12, -0.27, 0.42],
    ];
    let init_dir = [[6.0, -7.0, 2.0], [-3.0, 8.0, 5.0], [8.0, 2.0, -5.0], [-2.0, -4.0, 9.0]];
    let covs = [
        cov([0.18, 0.12, 0.22], 0.55, 0.3, -0.2),
        cov([0.25, 0.15, 0.35], -0.6, 0.4, 0.1),
        cov([0.14, 0.3, 0.28], 0.2, -0.5, 0.35),
        cov([0.1, 0.22, 0.4], -0.35, 0.2, 0.6),
    ];
    let anchors = (0..4)
        .map(|i| AnchorPlotEntry {
            label: format!("A{}", i + 1),
            nominal_m: truth[i],
            initial_m: Some(add(truth[i], along(init_dir[i], 10.0))),
            estimate_m: add(truth[i], est_off[i]),
            covariance_m2: Some(covs[i]),
            truth_m: Some(truth[i]),
        })
        .collect();
    // Deterministic pseudo-random platform positions within +-30 m x/y, z 0..25.
    let mut state: u64 = 0x2545_f491_4f6c_dd1d;
    let mut next = || {
        state ^= state << 13;
        state ^= state >> 7;
        state ^= state << 17;
        (state >> 11) as f64 / (1u64 << 53) as f64
    };
    let platform_positions_m = (0..80)
        .map(|_| [-30.0 + 60.0 * next(), -30.0 + 60.0 * next(), 25.0 * next()])
        .collect();
    AnchorPlot {
        title: "Anchor calibration: large robot, simulated".into(),
        caption: "sagcal calibrate --robot large --simulate --seed 42 --noise 0.01   (initial guesses 10 m off)".into(),
        anchors,
        platform_positions_m,
    }
}

fn entry(cov: Option<[[f64; 3]; 3]>) -> AnchorPlotEntry {
    AnchorPlotEntry {
        label: "A1".into(),
        nominal_m: [-125.0, -110.0, 48.0],
        initial_m: None,
        estimate_m: [-125.0, -110.0, 48.0],
        covariance_m2: cov,
        truth_m: Some([-125.0, -110.0, 48.0]),
    }
}

fn single(e: AnchorPlotEntry) -> AnchorPlot {
    AnchorPlot {
        title: "t".into(),
        caption: "c".into(),
        anchors: vec![e],
        platform_positions_m: vec![[0.0, 0.0, 10.0]],
    }
}

// ---------------------------------------------------------------------------
// Tests.

#[test]
fn example_is_well_formed_and_complete() {
    let plot = example_plot();
    let svg = anchor_plot_svg(&plot);
    let elems = assert_well_formed(&svg);
    for label in ["A1", "A2", "A3", "A4"] {
        assert!(svg.contains(&format!(">{label}<")), "label {label} missing");
    }
    assert!(svg.contains("Anchor calibration: large robot, simulated"));
    assert!(svg.contains("--seed 42"));
    // One 1-sigma/3-sigma pair per anchor in each view.
    for view in ["xy", "xz"] {
        assert_eq!(ellipses(&elems, view, 1).len(), 4);
        assert_eq!(ellipses(&elems, view, 3).len(), 4);
    }
    // Eight zoomed panels, each fitting estimate, truth and the 3-sigma ellipse.
    let panels: Vec<&Elem> = elems
        .iter()
        .filter(|e| e.name == "g" && e.attrs.get("class").map(String::as_str) == Some("panel"))
        .collect();
    assert_eq!(panels.len(), 8);
    for (i, a) in plot.anchors.iter().enumerate() {
        let c = a.covariance_m2.unwrap();
        for (k, (iu, iv)) in [(0, 1), (0, 2)].into_iter().enumerate() {
            let half = num(&panels[2 * i + k].attrs["data-half-range-m"]);
            let t = a.truth_m.unwrap();
            let du = (a.estimate_m[iu] - t[iu]).abs() + 3.0 * c[iu][iu].sqrt();
            let dv = (a.estimate_m[iv] - t[iv]).abs() + 3.0 * c[iv][iv].sqrt();
            assert!(half >= 1.05 * du.max(dv) && half >= 0.05, "panel {i}/{k}: half {half}");
            assert!(half < 3.0 * du.max(dv), "panel {i}/{k} zoomed out too far: {half}");
        }
    }
    // The initial guesses are 10 m away: off every panel, so drawn as arrows
    // labelled with their in-plane distance from the panel centre.
    let labels: Vec<f64> = elems
        .iter()
        .filter(|e| e.attrs.get("class").map(String::as_str) == Some("off-panel"))
        .map(|e| num(&e.attrs["data-distance-m"]))
        .collect();
    assert_eq!(labels.len(), 8);
    for (i, a) in plot.anchors.iter().enumerate() {
        let (p, t) = (a.initial_m.unwrap(), a.truth_m.unwrap());
        for (k, (iu, iv)) in [(0, 1), (0, 2)].into_iter().enumerate() {
            let d = (p[iu] - t[iu]).hypot(p[iv] - t[iv]);
            assert!((labels[2 * i + k] - d).abs() < 1e-6, "{} vs {d}", labels[2 * i + k]);
        }
    }
    assert!(svg.contains(">initial<"));
    let path = std::env::temp_dir().join("anchor_plot_example.svg");
    write_figure(&path, &svg).unwrap();
    assert_eq!(std::fs::read_to_string(&path).unwrap(), svg);
}

#[test]
fn diagonal_covariance_gives_axis_aligned_ellipse_of_right_size() {
    let c = [[4.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 9.0]];
    let svg = anchor_plot_svg(&single(entry(Some(c))));
    let elems = assert_well_formed(&svg);
    // (view, 1-sigma semi-axes, angle)
    for (view, major, minor, angle) in [("xy", 2.0, 1.0, 0.0), ("xz", 3.0, 2.0, 90.0)] {
        for k in [1u32, 3] {
            let found = ellipses(&elems, view, k);
            assert_eq!(found.len(), 1, "{view} sigma {k}");
            let e = found[0];
            let scale = num(&e.panel.as_ref().unwrap()["data-scale-px-per-m"]);
            let axes = nums(&e.attrs["data-semi-axes-m"]);
            let kf = k as f64;
            assert!(
                (axes[0] - kf * major).abs() < 1e-6 && (axes[1] - kf * minor).abs() < 1e-6,
                "{axes:?}"
            );
            assert!((num(&e.attrs["rx"]) - kf * major * scale).abs() < 1e-3);
            assert!((num(&e.attrs["ry"]) - kf * minor * scale).abs() < 1e-3);
            assert!((num(&e.attrs["data-angle-deg"]) - angle).abs() < 1e-6);
        }
    }
    // The exact attribute form the brief asks for.
    assert!(svg.contains(r#"data-semi-axes-m="2.000000 1.000000""#));
}

#[test]
fn correlated_covariance_rotates_the_ellipse() {
    let (a, b, d) = (0.09, 0.05, 0.04);
    let c = [[a, b, -0.01], [b, d, 0.0], [-0.01, 0.0, 0.02]];
    let svg = anchor_plot_svg(&single(entry(Some(c))));
    let elems = assert_well_formed(&svg);
    let (major, minor, angle) = closed_form(a, b, d);
    // Independent check of the closed form: (cos, sin) of the angle is the major eigenvector.
    let (cs, sn) = (angle.to_radians().cos(), angle.to_radians().sin());
    let lambda = major * major;
    assert!((a * cs + b * sn - lambda * cs).abs() < 1e-12 && (b * cs + d * sn - lambda * sn).abs() < 1e-12);
    assert!(angle > 0.0 && angle < 90.0);

    let e = ellipses(&elems, "xy", 1)[0];
    let axes = nums(&e.attrs["data-semi-axes-m"]);
    assert!((axes[0] - major).abs() < 1e-6 && (axes[1] - minor).abs() < 1e-6);
    assert!((num(&e.attrs["data-angle-deg"]) - angle).abs() < 1e-5);
    // SVG's y axis points down, so the drawn rotation is the negated data angle.
    let transform = &e.attrs["transform"];
    let inner = transform
        .strip_prefix("rotate(")
        .and_then(|t| t.strip_suffix(')'))
        .unwrap();
    let r = nums(inner);
    assert!((r[0] + angle).abs() < 1e-3, "{transform} vs {angle}");
    assert!((r[1] - num(&e.attrs["cx"])).abs() < 1e-9 && (r[2] - num(&e.attrs["cy"])).abs() < 1e-9);

    // Negative correlation in x-z: angle in (-90, 0).
    let e = ellipses(&elems, "xz", 1)[0];
    let (_, _, angle_xz) = closed_form(a, -0.01, 0.02);
    assert!(angle_xz < 0.0);
    assert!((num(&e.attrs["data-angle-deg"]) - angle_xz).abs() < 1e-5);
}

#[test]
fn zoom_is_at_least_five_centimetres() {
    let c = [[1e-8, 0.0, 0.0], [0.0, 1e-8, 0.0], [0.0, 0.0, 1e-8]];
    let svg = anchor_plot_svg(&single(entry(Some(c))));
    let elems = assert_well_formed(&svg);
    for e in elems
        .iter()
        .filter(|e| e.attrs.get("class").map(String::as_str) == Some("panel"))
    {
        assert!(num(&e.attrs["data-half-range-m"]) >= 0.05);
    }
}

#[test]
fn bad_covariances_skip_the_ellipse() {
    let not_pd = [[1.0, 2.0, 0.0], [2.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
    let nan = [[f64::NAN, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
    let zero = [[0.0; 3]; 3];
    for c in [Some(not_pd), Some(nan), Some(zero), None] {
        let svg = anchor_plot_svg(&single(entry(c)));
        let elems = assert_well_formed(&svg);
        assert!(elems.iter().all(|e| !e.attrs.contains_key("data-semi-axes-m")));
        assert!(svg.contains("covariance n/a"));
    }
}

#[test]
fn nan_and_infinite_inputs_do_not_panic() {
    let nan = f64::NAN;
    let inf = f64::INFINITY;
    let mut plot = example_plot();
    plot.title = "<script>&\"quotes\" 'apos'\u{1}\n".into();
    plot.caption = "a < b && c > d".into();
    plot.anchors[0].estimate_m = [nan, 0.0, 0.0];
    plot.anchors[1].truth_m = Some([inf, -inf, nan]);
    plot.anchors[1].covariance_m2 = Some([[inf; 3]; 3]);
    plot.anchors[2].initial_m = Some([nan; 3]);
    plot.anchors[2].nominal_m = [nan; 3];
    plot.anchors[3].estimate_m = [nan; 3];
    plot.anchors[3].truth_m = None;
    plot.anchors[3].label = "A&4 <x>".into();
    plot.anchors.push(AnchorPlotEntry {
        label: "huge".into(),
        nominal_m: [1e300, -1e300, 0.0],
        initial_m: None,
        estimate_m: [1e300, 1e300, 1e300],
        covariance_m2: Some([[1e300, 0.0, 0.0], [0.0, 1e300, 0.0], [0.0, 0.0, 1e300]]),
        truth_m: Some([-1e300, 0.0, 0.0]),
    });
    plot.platform_positions_m.push([nan, inf, 0.0]);
    let svg = anchor_plot_svg(&plot);
    assert_well_formed(&svg);
    assert!(svg.contains("&lt;script&gt;&amp;&quot;quotes&quot; &apos;apos&apos;"));
    assert!(svg.contains("a &lt; b &amp;&amp; c &gt; d"));
    assert!(svg.contains("A&amp;4 &lt;x&gt;"));
    assert!(svg.contains("covariance n/a"));

    // Nothing finite at all.
    let empty = AnchorPlot::default();
    assert_well_formed(&anchor_plot_svg(&empty));
    let all_nan = AnchorPlot {
        anchors: vec![AnchorPlotEntry {
            label: String::new(),
            nominal_m: [nan; 3],
            initial_m: Some([inf; 3]),
            estimate_m: [nan; 3],
            covariance_m2: Some([[nan; 3]; 3]),
            truth_m: Some([nan; 3]),
        }],
        platform_positions_m: vec![[nan; 3]],
        ..AnchorPlot::default()
    };
    assert_well_formed(&anchor_plot_svg(&all_nan));
}

fn dir_entries(dir: &Path) -> Vec<String> {
    let mut v: Vec<String> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    v.sort();
    v
}

#[test]
fn write_figure_to_missing_directory_fails_naming_the_path_and_leaves_nothing() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("no-such-dir").join("plot.svg");
    let err = write_figure(&path, "<svg/>").unwrap_err();
    assert!(matches!(err, sagcal::Error::Io { .. }), "{err:?}");
    assert!(err.to_string().contains(&path.display().to_string()), "{err}");
    assert!(!path.exists());
    assert!(!dir.path().join("no-such-dir").exists());
    assert!(dir_entries(dir.path()).is_empty());
}

#[test]
fn write_figure_replaces_atomically() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("plot.svg");
    write_figure(&path, "first").unwrap();
    write_figure(&path, "second").unwrap();
    assert_eq!(std::fs::read_to_string(&path).unwrap(), "second");
    assert_eq!(dir_entries(dir.path()), vec!["plot.svg".to_owned()]);
    // A directory in the way is an error naming the path, and leaves no temp file.
    let sub = dir.path().join("sub");
    std::fs::create_dir(&sub).unwrap();
    let err = write_figure(&sub, "x").unwrap_err();
    assert!(err.to_string().contains(&sub.display().to_string()));
    assert_eq!(dir_entries(dir.path()), vec!["plot.svg".to_owned(), "sub".to_owned()]);
}

// ---------------------------------------------------------------------------
// PNG.

/// Width and height of a PNG, from its IHDR chunk.
fn png_size(png: &[u8]) -> (u32, u32) {
    assert_eq!(&png[..8], b"\x89PNG\r\n\x1a\n", "PNG signature");
    assert_eq!(&png[12..16], b"IHDR");
    let be = |b: &[u8]| u32::from_be_bytes([b[0], b[1], b[2], b[3]]);
    (be(&png[16..20]), be(&png[20..24]))
}

/// Pixels darker than mid grey in a rendered PNG.
fn ink(png: &[u8]) -> usize {
    let pixmap = resvg::tiny_skia::Pixmap::decode_png(png).expect("decodes");
    pixmap
        .pixels()
        .iter()
        .filter(|p| u32::from(p.red()) + u32::from(p.green()) + u32::from(p.blue()) < 3 * 128)
        .count()
}

/// The `width="..."` and `height="..."` of an SVG's root element.
fn svg_size(svg: &str) -> (f64, f64) {
    let root = &svg[svg.find("<svg").unwrap()..];
    let attr = |name: &str| -> f64 {
        let at = root.find(&format!(" {name}=\"")).unwrap() + name.len() + 3;
        root[at..at + root[at..].find('"').unwrap()].parse().unwrap()
    };
    (attr("width"), attr("height"))
}

#[test]
fn text_is_drawn_with_the_bundled_regular_and_bold_fonts() {
    // Without a font resvg draws no text at all: the ink is the glyphs'.
    let svg = |weight: &str| {
        format!(
            r#"<svg xmlns="http://www.w3.org/2000/svg" width="300" height="40"><text x="4" y="28" font-family="Helvetica, sans-serif" font-size="24" font-weight="{weight}">Anchor 1 sigma</text></svg>"#
        )
    };
    let regular = ink(&svg_to_png(&svg("normal"), 1.0, "regular").unwrap());
    let bold = ink(&svg_to_png(&svg("bold"), 1.0, "bold").unwrap());
    assert!(regular > 300, "regular text ink {regular} px");
    // DejaVu Sans Bold's strokes are thicker: the bold face is loaded, not the regular one again.
    assert!(
        bold as f64 > 1.25 * regular as f64,
        "bold {bold} vs regular {regular} px"
    );
    let empty = r#"<svg xmlns="http://www.w3.org/2000/svg" width="300" height="40"></svg>"#;
    assert_eq!(ink(&svg_to_png(empty, 1.0, "empty").unwrap()), 0);
}

#[test]
fn png_figures_are_the_svg_at_twice_the_pixels() {
    let dir = tempfile::tempdir().unwrap();
    let svg = anchor_plot_svg(&example_plot());
    let path = dir.path().join("anchors.PNG");
    write_figure(&path, &svg).unwrap();
    let png = std::fs::read(&path).unwrap();
    let (w, h) = svg_size(&svg);
    assert_eq!(
        png_size(&png),
        ((PNG_SCALE as f64 * w) as u32, (PNG_SCALE as f64 * h) as u32)
    );
    assert!(ink(&png) > 10_000, "the figure is drawn");
    // Any other name is the SVG text itself.
    let other = dir.path().join("anchors.png.svg");
    write_figure(&other, &svg).unwrap();
    assert_eq!(std::fs::read_to_string(&other).unwrap(), svg);
    // A broken SVG is an error naming the file, and nothing is written.
    let bad = dir.path().join("bad.png");
    let err = write_figure(&bad, "<svg").unwrap_err();
    assert!(err.to_string().contains("bad.png"), "{err}");
    assert!(!bad.exists());
}

#[test]
fn long_titles_and_captions_wrap_inside_the_residual_figure() {
    let title = "sagcal diagnose `large`: load_cell residual vs mid-span sag (m) (verdict: none)".to_string();
    let caption = "m.csv; held-out residual RMS 0.801 -> 0.801 (no hypothesis is significant at false-alarm rate \
                   1e-3: the baseline model stands)"
        .to_string();
    let plot = ResidualPlot {
        title: title.clone(),
        driver_label: "mid-span sag (m)".into(),
        residual_label: "load_cell residual / sigma".into(),
        before: ResidualSeries {
            label: "baseline model".into(),
            points: (0..20).map(|i| (i as f64, 0.1 * i as f64)).collect(),
        },
        after: None,
        caption: caption.clone(),
    };
    let svg = residual_plot_svg(&plot);
    let (width, height) = svg_size(&svg);
    // Every line of the title (20 px, bold) and caption (12 px) fits the width at
    // DejaVu's widest average advance, 0.62 em; all their words are there.
    let lines = |class: &str| -> Vec<String> {
        let at = svg.find(&format!(r#"class="{class}""#)).unwrap();
        let end = at + svg[at..].find("</text>").unwrap();
        svg[at..end]
            .split("<tspan")
            .skip(1)
            .map(|t| t[t.find('>').unwrap() + 1..t.find("</tspan>").unwrap()].to_string())
            .collect()
    };
    for (class, font, text) in [("title", 20.0, &title), ("caption", 12.0, &caption)] {
        let got = lines(class);
        assert!(got.len() >= 2, "{class}: {got:?}");
        for line in &got {
            assert!(
                20.0 + line.chars().count() as f64 * 0.62 * font <= width,
                "{class} line {line:?}"
            );
        }
        assert_eq!(got.join(" ").replace("&gt;", ">"), *text);
    }
    assert!(height > 520.0, "the figure grows with the extra lines: {height}");
}
