//! End-to-end tests of the plots: `seqsmooth demo` (its summary, PNG and SVG) and `seqsmooth
//! plot` on the output of every filter kind, and the plot command's errors and exit codes.
//!
//! The images are checked by their structure: a PNG's signature, its IHDR dimensions and a size
//! far above that of a blank image of the same dimensions (a white 1400×1030 PNG compresses to
//! about 7 KB); an SVG's text (title, axis labels, legend entries) and its element counts.

use std::path::{Path, PathBuf};

mod common;
use common::{run_at, Out};

fn run_in(dir: &Path, args: &[&str], stdin: &str) -> Out {
    run_at(Some(dir), args, stdin)
}

fn ok_in(dir: &Path, args: &[&str], stdin: &str) -> String {
    let o = run_in(dir, args, stdin);
    assert_eq!(o.code, 0, "seqsmooth {args:?} failed: {}", o.stderr);
    o.stdout
}

/// Runs and asserts failure with `code` and every `parts` in stderr.
fn fails_in(dir: &Path, args: &[&str], stdin: &str, code: i32, parts: &[&str]) {
    let o = run_in(dir, args, stdin);
    assert_eq!(o.code, code, "seqsmooth {args:?}: stderr {}", o.stderr);
    assert!(o.stderr.starts_with("error: "), "{}", o.stderr);
    for p in parts {
        assert!(o.stderr.contains(p), "stderr lacks {p:?}: {}", o.stderr);
    }
    assert!(!o.stderr.contains("panicked"), "{}", o.stderr);
}

/// A fresh, empty directory for one test.
fn fresh_dir(name: &str) -> PathBuf {
    let dir = PathBuf::from(env!("CARGO_TARGET_TMPDIR"))
        .join("plot-tests")
        .join(name);
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// The PNG's width and height from its IHDR chunk, after checking the signature.
fn png_size(path: &Path) -> (u32, u32) {
    let b = std::fs::read(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    assert!(b.len() > 33, "{} is too short for a PNG", path.display());
    assert_eq!(
        &b[..8],
        b"\x89PNG\r\n\x1a\n",
        "PNG signature of {}",
        path.display()
    );
    assert_eq!(&b[8..16], b"\x00\x00\x00\x0dIHDR", "IHDR first");
    let be = |i: usize| u32::from_be_bytes([b[i], b[i + 1], b[i + 2], b[i + 3]]);
    (be(16), be(20))
}

fn file_size(path: &Path) -> u64 {
    std::fs::metadata(path)
        .unwrap_or_else(|e| panic!("{}: {e}", path.display()))
        .len()
}

fn count(text: &str, what: &str) -> usize {
    text.matches(what).count()
}

/// The default image height: 120 for the title and legend, 330 per derivative panel, 250 for
/// the residual panel (`chart::Layout::default_height`).
fn default_height(panels: u32, residual: bool) -> u32 {
    120 + 330 * panels + if residual { 250 } else { 0 }
}

// ---------------------------------------------------------------------------------------------
// demo

/// `seqsmooth demo` in an empty directory writes seqsmooth-demo.png and .svg there: a PNG of
/// 1400 × 1030 (two derivative panels and the residuals) far above a blank image's size, and an
/// SVG with the title, axis labels, every legend entry the demo's data call for, a dot per
/// accepted sample and a cross per rejected one. The summary reports what the plot shows.
#[test]
fn demo_writes_png_and_svg_in_the_current_directory() {
    let dir = fresh_dir("demo-default");
    let o = run_in(&dir, &["demo"], "");
    assert_eq!(o.code, 0, "{}", o.stderr);
    let png = dir.join("seqsmooth-demo.png");
    let svg = dir.join("seqsmooth-demo.svg");
    assert_eq!(png_size(&png), (1400, default_height(2, true)));
    assert!(
        file_size(&png) > 60_000,
        "PNG only {} bytes",
        file_size(&png)
    );
    assert!(o.stderr.contains("seqsmooth-demo.png") && o.stderr.contains("seqsmooth-demo.svg"));

    let text = std::fs::read_to_string(&svg).unwrap();
    assert!(text.starts_with("<svg") && text.contains("width=\"1400\""));
    // The SVG names the font the PNG embeds, with the viewer's sans-serif as the fallback.
    let families = count(&text, "font-family=\"");
    assert!(families > 20, "{families} texts");
    assert_eq!(
        count(&text, "font-family=\"DejaVu Sans, sans-serif\""),
        families
    );
    for label in [
        "seqsmooth demo: automatic filter on a turning aircraft",
        "time (s)",
        "east position error: estimate − truth (m)",
        "east velocity (m/s)",
        "residual y − estimate (m)",
        "truth − estimate",
        "no samples (outage)",
        "samples",
        "rejected (outlier)",
        "estimate ±3σ",
        "truth",
        "noise ±3σ",
        "switch to fading memory",
        "misfit restart",
        "misfit flagged",
    ] {
        assert!(text.contains(label), "SVG lacks {label:?}");
    }
    // Summary: "rejected R samples: C of the N outliers, G good samples".
    let line = o
        .stdout
        .lines()
        .find(|l| l.trim_start().starts_with("rejected "))
        .unwrap_or_else(|| panic!("no rejected line: {}", o.stdout));
    let nums: Vec<usize> = line
        .split(|c: char| !c.is_ascii_digit())
        .filter(|s| !s.is_empty())
        .map(|s| s.parse().unwrap())
        .collect();
    let (rejected, caught, outliers, good) = (nums[0], nums[1], nums[2], nums[3]);
    assert_eq!(rejected, caught + good, "{line}");
    assert!(outliers >= 3 && caught >= outliers - 1, "{line}");
    // A dot per sample in the position and residual panels (less the clipped and rejected
    // ones), a cross (two lines) per rejected sample in each of those panels and the legend.
    let circles = count(&text, "<circle");
    assert!(circles >= 2 * (400 - rejected) - 40, "{circles} circles");
    assert!(circles <= 2 * 400 + 1, "{circles} circles");
    assert!(count(&text, "<polygon") >= 3, "bands");
    assert!(count(&text, "<polyline") >= 6, "lines");
    for word in [
        "switch from expanding to fading memory: t = ",
        "misfit restarts: ",
    ] {
        assert!(o.stdout.contains(word), "{}", o.stdout);
    }
    // The automatic filter beats the plain ones on this track (the table's "rms err x").
    let rms = |name: &str, engine: &str| -> f64 {
        let row = o
            .stdout
            .lines()
            .find(|l| {
                let mut w = l.split_whitespace();
                w.next() == Some(name) && w.next() == Some(engine)
            })
            .unwrap_or_else(|| panic!("no {name} {engine} row: {}", o.stdout));
        row.split_whitespace().nth(2).unwrap().parse().unwrap()
    };
    let auto = rms("automatic", "exact");
    assert!(auto < 20.0, "automatic rms {auto}");
    for (name, engine) in [
        ("fading", "exact"),
        ("expanding", "exact"),
        ("fading", "gain"),
    ] {
        assert!(auto < rms(name, engine) / 3.0, "{name} {engine}");
    }
}

/// `--plot PREFIX` writes PREFIX.png and PREFIX.svg (a trailing .png/.svg is dropped), with
/// `-o` still writing the CSV; `--no-plot` writes no image; the output is deterministic.
#[test]
fn demo_plot_prefix_and_no_plot() {
    let dir = fresh_dir("demo-prefix");
    std::fs::create_dir_all(dir.join("sub")).unwrap();
    let a = ok_in(&dir, &["demo", "--plot", "sub/run", "-o", "d.csv"], "");
    assert_eq!(png_size(&dir.join("sub/run.png")), (1400, 1030));
    assert!(file_size(&dir.join("sub/run.svg")) > 50_000);
    let csv = std::fs::read_to_string(dir.join("d.csv")).unwrap();
    assert!(csv.starts_with("t,y,d0,d1,d2,s0,s1,s2\n"));
    assert_eq!(csv.lines().count(), 401);

    let b = ok_in(&dir, &["demo", "--plot", "again.svg"], "");
    assert_eq!(a, b, "the summary is deterministic");
    assert!(dir.join("again.png").exists() && dir.join("again.svg").exists());
    assert_eq!(
        std::fs::read(dir.join("sub/run.svg")).unwrap(),
        std::fs::read(dir.join("again.svg")).unwrap(),
        "the SVG is deterministic"
    );

    let quiet = fresh_dir("demo-no-plot");
    ok_in(&quiet, &["demo", "--no-plot"], "");
    assert_eq!(std::fs::read_dir(&quiet).unwrap().count(), 0);
    fails_in(
        &quiet,
        &["demo", "--no-plot", "--plot", "x"],
        "",
        2,
        &["--plot"],
    );
}

/// A plot that cannot be written is a data error naming the file.
#[test]
fn demo_plot_to_a_missing_directory_fails() {
    let dir = fresh_dir("demo-bad-dir");
    fails_in(
        &dir,
        &["demo", "--plot", "no/such/dir/p"],
        "",
        1,
        &["cannot write the plot to 'no/such/dir/p.png'"],
    );
}

// ---------------------------------------------------------------------------------------------
// plot

/// A test series: a parabola sampled at jittered times with a deterministic ±0.5 noise pattern,
/// a spike of 30 at row 150 and a truth column.
fn series() -> String {
    let mut s = String::from("t,y,truth\n");
    let mut t = 0.0;
    for i in 0..300u64 {
        t += 0.5 + 0.1 * (((i * 7919) % 11) as f64 / 10.0 - 0.5);
        let truth = 3.0 + 2.0 * t - 0.05 * t * t;
        let noise = 0.5 * (((i * 37 + 11) % 17) as f64 / 8.0 - 1.0);
        let spike = if i == 150 { 30.0 } else { 0.0 };
        s += &format!("{t},{},{truth}\n", truth + noise + spike);
    }
    s
}

/// Runs `seqsmooth filter data.csv ARGS -o NAME.csv` in `dir` and returns NAME.csv's path.
fn filter_output(dir: &Path, name: &str, args: &[&str]) -> PathBuf {
    let out = format!("{name}.csv");
    let mut all = vec!["filter", "data.csv"];
    all.extend_from_slice(args);
    all.extend_from_slice(&["-o", &out]);
    ok_in(dir, &all, "");
    dir.join(out)
}

fn svg_of(path: &Path) -> String {
    let text = std::fs::read_to_string(path).unwrap();
    assert!(text.starts_with("<svg"), "{}", path.display());
    text
}

/// One plot case: the output's name, the filter's arguments, what the SVG has and lacks.
type Case<'a> = (&'a str, &'a [&'a str], &'a [&'a str], &'a [&'a str]);

/// Every filter kind's output plots to PNG and SVG; the legend holds what the columns give:
/// bands with s columns only, rejected samples, noise lines and misfit spans only for auto.
#[test]
fn plot_every_filter_kind() {
    let dir = fresh_dir("plot-kinds");
    std::fs::write(dir.join("data.csv"), series()).unwrap();
    let cases: [Case; 5] = [
        (
            "expanding",
            &["--kind", "expanding", "--degree", "2"],
            &["samples", "estimate"],
            &["estimate ±3σ", "rejected", "noise ±3σ", "truth"],
        ),
        (
            "expanding-sigma",
            &["--kind", "expanding", "--degree", "2", "--sigma", "0.5"],
            &["estimate ±3σ"],
            &["rejected", "noise ±3σ"],
        ),
        (
            "fading",
            &[
                "--kind", "fading", "--degree", "2", "--theta", "0.9", "--sigma", "0.5",
            ],
            &["estimate ±3σ", "seqsmooth filter output: fading.csv"],
            &["rejected"],
        ),
        (
            "fixed",
            &[
                "--kind", "fixed", "--degree", "2", "--window", "21", "--sigma", "0.5",
            ],
            &[
                "estimate ±3σ",
                "seqsmooth fixed-memory filter output: fixed.csv",
            ],
            &["rejected"],
        ),
        (
            "auto",
            &["--kind", "auto", "--degree", "2", "--theta", "0.9"],
            &[
                "estimate ±3σ",
                "rejected (outlier)",
                "noise ±3σ",
                "seqsmooth automatic filter output: auto.csv",
            ],
            &["truth"],
        ),
    ];
    for (name, args, has, lacks) in cases {
        let out = filter_output(&dir, name, args);
        let png = format!("{name}.png");
        let svg = format!("{name}.svg");
        ok_in(
            &dir,
            &["plot", out.to_str().unwrap(), "-o", &png, "-o", &svg],
            "",
        );
        assert_eq!(png_size(&dir.join(&png)), (1200, default_height(1, true)));
        assert!(file_size(&dir.join(&png)) > 30_000, "{name}");
        let text = svg_of(&dir.join(&svg));
        for h in has {
            assert!(text.contains(h), "{name}: SVG lacks {h:?}");
        }
        for l in lacks {
            assert!(!text.contains(l), "{name}: SVG has {l:?}");
        }
        for axis in ["time t", "residual y − d0", "\ny\n"] {
            assert!(text.contains(axis), "{name}: SVG lacks {axis:?}");
        }
        // a dot per sample in the value panel and per estimated row in the residual panel
        assert!(count(&text, "<circle") >= 300 + 250, "{name}");
    }
}

/// Two derivative panels with units, a title, a size; standard input as the source; the
/// input's truth column; with a lead the residual panel compares the estimates with the samples
/// at their time t + H (`plot_compares_a_lead_with_the_sample_at_its_time`).
#[test]
fn plot_options() {
    let dir = fresh_dir("plot-options");
    std::fs::write(dir.join("data.csv"), series()).unwrap();
    let out = filter_output(
        &dir,
        "auto",
        &["--kind", "auto", "--degree", "2", "--theta", "0.9"],
    );
    let text = std::fs::read_to_string(&out).unwrap();
    ok_in(
        &dir,
        &[
            "plot",
            "-",
            "-o",
            "two.png",
            "-o",
            "two.svg",
            "--derivative",
            "0",
            "--derivative",
            "2",
            "--time-unit",
            "s",
            "--value-unit",
            "m",
            "--title",
            "My title",
        ],
        &text,
    );
    assert_eq!(
        png_size(&dir.join("two.png")),
        (1200, default_height(2, true))
    );
    let svg = svg_of(&dir.join("two.svg"));
    for label in [
        "My title",
        "time t (s)",
        "y (m)",
        "d²y/dt² (m/s²)",
        "residual y − d0 (m)",
    ] {
        assert!(svg.contains(label), "SVG lacks {label:?}");
    }
    assert!(!svg.contains("dy/dt (m/s)"));

    ok_in(
        &dir,
        &[
            "plot",
            "auto.csv",
            "-o",
            "small.png",
            "--width",
            "640",
            "--height",
            "480",
        ],
        "",
    );
    assert_eq!(png_size(&dir.join("small.png")), (640, 480));

    ok_in(
        &dir,
        &[
            "plot",
            "auto.csv",
            "-o",
            "truth.svg",
            "--input",
            "data.csv",
            "--truth-col",
            "truth",
        ],
        "",
    );
    assert!(svg_of(&dir.join("truth.svg")).contains("truth"));

    let lead = filter_output(
        &dir,
        "lead",
        &[
            "--kind", "fading", "--degree", "1", "--theta", "0.9", "--lead", "2",
        ],
    );
    ok_in(
        &dir,
        &[
            "plot",
            lead.to_str().unwrap(),
            "-o",
            "lead.svg",
            "--lead",
            "2",
            "--no-residuals",
        ],
        "",
    );
    let svg = svg_of(&dir.join("lead.svg"));
    assert!(!svg.contains("residual") && svg.contains("estimates drawn at t + 2"));
    // Without --no-residuals the rows whose t + 2 is a sample time are compared with it.
    ok_in(
        &dir,
        &[
            "plot",
            "lead.csv",
            "-o",
            "lead2.png",
            "-o",
            "lead2.svg",
            "--lead",
            "2",
        ],
        "",
    );
    assert_eq!(
        png_size(&dir.join("lead2.png")),
        (1200, default_height(1, true))
    );
    assert!(svg_of(&dir.join("lead2.svg")).contains("residuals against the sample at t + 2 ("));
}

/// Bad input is a data error (exit 1) naming the file, line and column; bad arguments are
/// usage errors (exit 2); no image is written.
#[test]
fn plot_errors() {
    let dir = fresh_dir("plot-errors");
    let write = |name: &str, text: &str| std::fs::write(dir.join(name), text).unwrap();
    let good = "t,y,d0,d1,s0,s1,noise,outlier,misfit\n0,1,1,,,,,0,0\n1,2,2,1,0.5,0.2,0.4,0,0\n";
    write("good.csv", good);
    write("ragged.csv", "t,y,d0\n0,1,1\n1,2\n");
    write("nod0.csv", "t,y\n0,1\n1,2\n");
    write("word.csv", "t,y,d0,d1\n0,1,1,\n1,2,2,1\n\n2,3,3,abc\n");
    write("flag.csv", "t,y,d0,outlier\n0,1,1,0\n1,2,2,2\n");
    write("neg.csv", "t,y,d0,s0\n0,1,1,0.1\n1,2,2,-0.1\n");
    write("inf.csv", "t,y,d0\n0,1,1\n1,inf,2\n");
    write("emptyt.csv", "t,y,d0\n0,1,1\n,2,2\n");
    write("header.csv", "t,y,d0\n");
    write("empty.csv", "");
    write("in-short.csv", "t,y\n0,1\n");
    write("in-other.csv", "t,y\n0,1\n1.5,2\n");
    write("unsorted.csv", "t,y,d0\n0,1,1\n2,2,2\n1,3,3\n");
    write("duplicate.csv", "t,y,d0\n0,1,1\n0,2,2\n");
    write("twice.csv", "t,y,y,d0\n0,1,1,1\n1,2,2,2\n");
    let cases: [(&[&str], i32, &[&str]); 19] = [
        (
            &["plot", "unsorted.csv", "-o", "x.png"],
            1,
            &["'unsorted.csv': line 4, column 't': time 1 is not after the previous time 2 (line 3)"],
        ),
        (
            &["plot", "duplicate.csv", "-o", "x.png"],
            1,
            &["line 3, column 't': time 0 is not after the previous time 0 (line 2)"],
        ),
        (
            &["plot", "twice.csv", "-o", "x.png"],
            1,
            &["column 'y' appears more than once in the header (columns 2 and 3)"],
        ),
        (
            &["plot", "missing.csv", "-o", "x.png"],
            1,
            &["cannot open input file 'missing.csv'"],
        ),
        (
            &["plot", "ragged.csv", "-o", "x.png"],
            1,
            &["'ragged.csv': line 3: malformed CSV"],
        ),
        (
            &["plot", "nod0.csv", "-o", "x.png"],
            1,
            &["'nod0.csv': column 'd0' not found", "t, y"],
        ),
        (
            &["plot", "good.csv", "-o", "x.png", "--derivative", "2"],
            1,
            &[
                "'good.csv': column 'd2' not found",
                "degree must be at least 2",
            ],
        ),
        (
            &["plot", "word.csv", "-o", "x.png", "--derivative", "1"],
            1,
            &["'word.csv': line 5, column 'd1': 'abc' is not a number"],
        ),
        (
            &["plot", "flag.csv", "-o", "x.png"],
            1,
            &["line 3, column 'outlier': '2' is not a flag"],
        ),
        (
            &["plot", "neg.csv", "-o", "x.png"],
            1,
            &["line 3, column 's0'", "negative"],
        ),
        (
            &["plot", "inf.csv", "-o", "x.png"],
            1,
            &["'inf.csv': line 3, column 'y'", "not finite"],
        ),
        (
            &["plot", "emptyt.csv", "-o", "x.png"],
            1,
            &["line 3, column 't': the cell is empty"],
        ),
        (
            &["plot", "header.csv", "-o", "x.png"],
            1,
            &["'header.csv': no data rows"],
        ),
        (
            &["plot", "empty.csv", "-o", "x.png"],
            1,
            &["'empty.csv': the file is empty"],
        ),
        (
            &["plot", "good.csv", "-o", "x.png", "--input", "in-short.csv"],
            1,
            &["'in-short.csv' has 1 data row but", "'good.csv' has 2"],
        ),
        (
            &["plot", "good.csv", "-o", "x.png", "--input", "in-other.csv"],
            1,
            &["'in-other.csv': line 3, column 't': 1.5 differs from 1 on line 3"],
        ),
        (
            &["plot", "good.csv", "-o", "x.jpg"],
            2,
            &["'x.jpg'", ".png or .svg"],
        ),
        (
            &["plot", "good.csv", "-o", "x.png", "--truth-col", "x"],
            2,
            &["--input"],
        ),
        (&["plot", "good.csv"], 2, &["--output"]),
    ];
    for (args, code, parts) in cases {
        fails_in(&dir, args, "", code, parts);
        assert!(!dir.join("x.png").exists(), "{args:?} left an image");
    }
    fails_in(
        &dir,
        &[
            "plot",
            "good.csv",
            "-o",
            "x.png",
            "--input",
            "good.csv",
            "--truth-col",
            "z",
        ],
        "",
        1,
        &["column 'z' not found"],
    );
    fails_in(
        &dir,
        &["plot", "good.csv", "-o", "no/dir/x.svg"],
        "",
        1,
        &["cannot write the plot to 'no/dir/x.svg'"],
    );
    fails_in(
        &dir,
        &["plot", "good.csv", "-o", "x.png", "--width", "10"],
        "",
        2,
        &["10"],
    );
    // the good file itself plots
    ok_in(
        &dir,
        &["plot", "good.csv", "-o", "ok.svg", "--derivative", "1"],
        "",
    );
    assert!(svg_of(&dir.join("ok.svg")).contains("dy/dt"));
}

/// `filter --lead H` records H in a trailing `lead` column; `plot` reads it (no `--lead`
/// needed), draws each estimate at its own time t + H and compares it with the sample there:
/// on evenly spaced rows with H = 4 steps every row but the last four has one, and on a
/// straight line those residuals are zero (the axis then spans the default ±1.08). A lead
/// that matches no sample says so instead of comparing the estimate with the wrong sample; a
/// column with two leads, or a `--lead` that contradicts it, is an error.
#[test]
fn plot_compares_a_lead_with_the_sample_at_its_time() {
    let dir = fresh_dir("plot-lead-column");
    let mut data = String::from("t,y\n");
    for i in 0..100 {
        let t = 1.7e9 + 0.5 * i as f64;
        data += &format!("{t},{}\n", 3.0 + 2.0 * (t - 1.7e9));
    }
    std::fs::write(dir.join("data.csv"), &data).unwrap();
    let out = filter_output(
        &dir,
        "lead",
        &["--kind", "expanding", "--degree", "1", "--lead", "2"],
    );
    let text = std::fs::read_to_string(&out).unwrap();
    let mut lines = text.lines();
    assert_eq!(lines.next(), Some("t,y,d0,d1,lead"));
    assert!(lines.all(|l| l.ends_with(",2")), "{text}");
    ok_in(
        &dir,
        &["plot", "lead.csv", "-o", "lead.svg", "-o", "lead.png"],
        "",
    );
    let svg = svg_of(&dir.join("lead.svg"));
    assert!(
        svg.contains("estimates drawn at t + 2, their time; residuals against the sample at t + 2 (95 of 99 estimates have one)"),
        "{}",
        svg.lines().filter(|l| l.contains("estimates")).collect::<String>()
    );
    assert!(svg.contains("residual y − d0"));
    assert_eq!(
        png_size(&dir.join("lead.png")),
        (1200, default_height(1, true))
    );
    // The residuals of a straight line are zero: no residual stretches the axis.
    assert!(
        svg.contains("\n1.0\n") && svg.contains("\n-1.0\n"),
        "residual axis"
    );

    let odd = filter_output(
        &dir,
        "odd",
        &["--kind", "expanding", "--degree", "1", "--lead", "0.3"],
    );
    ok_in(&dir, &["plot", odd.to_str().unwrap(), "-o", "odd.svg"], "");
    let svg = svg_of(&dir.join("odd.svg"));
    assert!(svg.contains("no residuals: no sample is at the time of an estimate"));
    assert!(!svg.contains("residual y − d0"));

    fails_in(
        &dir,
        &["plot", "lead.csv", "-o", "x.png", "--lead", "3"],
        "",
        1,
        &[
            "'lead.csv'",
            "line 2, column 'lead'",
            "is not the --lead 3 given",
        ],
    );
    let mixed = text
        .replacen(",2\n", ",2.5\n", 2)
        .replacen(",2.5\n", ",2\n", 1);
    std::fs::write(dir.join("mixed.csv"), mixed).unwrap();
    fails_in(
        &dir,
        &["plot", "mixed.csv", "-o", "x.png"],
        "",
        1,
        &["line 3, column 'lead': 2.5 differs from the lead of the first row"],
    );
    assert!(!dir.join("x.png").exists());
}

/// A dense series (6,070 rows at 100 Hz, more than the 1,070 pixel columns of the plot) is
/// drawn decimated: its samples as one thin line instead of 6,070 dots, every curve at most
/// four points per pixel column; epoch-nanosecond times and a 1e-9-scale value get short tick
/// labels and axis labels that say how to read them.
#[test]
fn dense_epoch_series_is_decimated_with_readable_ticks() {
    let dir = fresh_dir("plot-dense");
    let mut data = String::from("t,y\n");
    for i in 0..6070u64 {
        let t = 1_700_000_000_000_000_000u64 + i * 10_000_000;
        let noise = ((i * 7919) % 101) as f64 / 100.0 - 0.5;
        let y = 2e-9 + 1e-9 * (i as f64 / 100.0).sin() + 2e-10 * noise;
        data += &format!("{t},{y:e}\n");
    }
    std::fs::write(dir.join("data.csv"), &data).unwrap();
    let fading = ["--kind", "fading", "--degree", "2", "--theta", "0.95"];
    filter_output(
        &dir,
        "dense",
        &[&fading[..], &["--sigma", "2e-10"]].concat(),
    );
    let plot = ["plot", "dense.csv", "-o", "dense.svg", "--time-unit", "ns"];
    ok_in(&dir, &plot, "");
    let svg = svg_of(&dir.join("dense.svg"));
    assert!(svg.contains("samples, lowest to highest per pixel (too dense for dots)"));
    assert!(
        count(&svg, "<circle") <= 2,
        "{} circles",
        count(&svg, "<circle")
    );
    // Every polyline has at most 4 points per pixel column of the plot.
    for line in svg.lines().filter(|l| l.starts_with("<polyline")) {
        let points = line.matches(',').count();
        assert!(points <= 4 * 1070 + 8, "a polyline of {points} points");
    }
    assert!(svg.contains(
        "time t (ns); t = t₀ + tick × 1e9, t₀ = 1.7e18 (as Unix ns: 2023-11-14 22:13:20 UTC)"
    ));
    assert!(svg.contains("y; value = tick × 1e-9"));
    // Tick labels: short numbers, none of them 19 digits or 0.00000000.
    let labels: Vec<&str> = svg
        .split("</text>")
        .filter_map(|t| t.rsplit('>').next().map(str::trim))
        .filter(|t| !t.is_empty() && t.chars().all(|c| c.is_ascii_digit() || "-.".contains(c)))
        .collect();
    assert!(labels.len() >= 20, "{labels:?}");
    assert!(labels.iter().all(|l| l.len() <= 10), "{labels:?}");
}

// ---------------------------------------------------------------------------------------------
// outages, values beyond the axis, dense automatic output

/// An SVG element: its tag's attributes.
type Element = std::collections::HashMap<String, String>;

/// The SVG's elements with tag `tag` (`<tag a="…" …/>`).
fn elements(svg: &str, tag: &str) -> Vec<Element> {
    let open = format!("<{tag} ");
    svg.split(open.as_str())
        .skip(1)
        .map(|rest| {
            let body = &rest[..rest.find("/>").unwrap_or(rest.len())];
            let mut attrs = Element::new();
            for part in body.split("\" ") {
                if let Some((k, v)) = part.split_once("=\"") {
                    attrs.insert(k.trim().to_string(), v.trim_end_matches('"').to_string());
                }
            }
            attrs
        })
        .collect()
}

fn attr(e: &Element, name: &str) -> f64 {
    e[name].parse().unwrap()
}

/// The vertices of a polyline or polygon.
fn vertices(e: &Element) -> Vec<(f64, f64)> {
    e["points"]
        .split_whitespace()
        .map(|p| {
            let (x, y) = p.split_once(',').unwrap();
            (x.parse().unwrap(), y.parse().unwrap())
        })
        .collect()
}

/// Colours (SVG) of the estimate and its band, the truth − estimate line, the noise lines and
/// a dense series' envelope: what must not be drawn across an outage.
const CURVES: [&str; 4] = ["#1F5AB4", "#00828C", "#E67800", "#787878"];
const OUTAGE_FILL: &str = "#6E6E6E";
const MISFIT_FILL: &str = "#E13C96";

/// The outages shaded in the SVG's panels: their pixel spans `(x0, x1)` (one per panel).
fn outage_spans(svg: &str) -> Vec<(f64, f64)> {
    elements(svg, "rect")
        .iter()
        .filter(|r| r.get("fill").map(String::as_str) == Some(OUTAGE_FILL))
        .filter(|r| attr(r, "height") > 40.0)
        .map(|r| (attr(r, "x"), attr(r, "x") + attr(r, "width")))
        .collect()
}

/// The segments of curve colours (polylines, polygons with their closing edge, lines) that
/// span one of `spans`, edge to edge or beyond.
fn segments_across(svg: &str, spans: &[(f64, f64)]) -> Vec<String> {
    let curve = |e: &Element| {
        ["stroke", "fill"]
            .iter()
            .any(|a| e.get(*a).is_some_and(|c| CURVES.contains(&c.as_str())))
    };
    let mut segs = Vec::new();
    for e in elements(svg, "polyline").iter().filter(|e| curve(e)) {
        segs.extend(vertices(e).windows(2).map(|w| (w[0], w[1])));
    }
    for e in elements(svg, "polygon").iter().filter(|e| curve(e)) {
        let v = vertices(e);
        segs.extend(v.windows(2).map(|w| (w[0], w[1])));
        if let (Some(&a), Some(&b)) = (v.last(), v.first()) {
            segs.push((a, b));
        }
    }
    for e in elements(svg, "line").iter().filter(|e| curve(e)) {
        segs.push((
            (attr(e, "x1"), attr(e, "y1")),
            (attr(e, "x2"), attr(e, "y2")),
        ));
    }
    let mut out = Vec::new();
    for (a, b) in segs {
        let (lo, hi) = (a.0.min(b.0), a.0.max(b.0));
        for &(x0, x1) in spans {
            // (an outage runs from the last sample before to the first after: a segment
            // drawn across it joins its two edges)
            if lo <= x0 + 0.5 && hi >= x1 - 0.5 {
                out.push(format!("{a:?}-{b:?} across {x0}..{x1}"));
            }
        }
    }
    out
}

/// The demo's 12 s outage is found by the plot's rule (and nothing else is), hatched, and no
/// curve is drawn across it: no segment of the estimate, its band, the truth − estimate line,
/// the noise lines crosses its span in any panel. The misfit shading is a colour of its own,
/// with its own legend entry. The start-up error beyond the error panel's axis is marked: a
/// triangle at the edge in the estimate's colour and a note of how far it goes.
#[test]
fn demo_breaks_at_the_outage_and_marks_values_beyond_the_axis() {
    let dir = fresh_dir("demo-outage");
    ok_in(&dir, &["demo", "--plot", "d.svg"], "");
    let svg = svg_of(&dir.join("d.svg"));
    let spans = outage_spans(&svg);
    // One outage, in each of the three panels, about 13 s of the 400 s wide.
    assert_eq!(spans.len(), 3, "{spans:?}");
    for &(x0, x1) in &spans {
        assert!((x1 - x0 - spans[0].1 + spans[0].0).abs() < 1.0);
        assert!(x1 - x0 > 30.0 && x1 - x0 < 60.0, "{x0}..{x1}");
    }
    // The hatching: lines inside the span.
    let hatches = elements(&svg, "polyline")
        .into_iter()
        .filter(|e| e["stroke"] == OUTAGE_FILL)
        .count();
    assert!(hatches >= 3 * 5, "{hatches} hatch lines");
    let across = segments_across(&svg, &spans);
    assert!(across.is_empty(), "drawn across the outage: {across:?}");
    // Misfit spans: their own colour, in the legend beside the outage's.
    let fills: Vec<String> = elements(&svg, "rect")
        .iter()
        .filter_map(|r| r.get("fill").cloned())
        .collect();
    assert!(fills.iter().any(|f| f == MISFIT_FILL), "no misfit shading");
    assert!(svg.contains("misfit flagged") && svg.contains("no samples (outage)"));
    // Beyond the axis: the note, the legend entry, and triangles of the estimate's colour.
    assert!(
        svg.contains("beyond the axis: estimate − truth reaches -"),
        "{}",
        svg.lines()
            .filter(|l| l.contains("beyond"))
            .collect::<Vec<_>>()
            .join("\n")
    );
    assert!(svg.contains("beyond the axis (at its edge)"));
    let marks = elements(&svg, "polygon")
        .into_iter()
        .filter(|e| e["fill"] == "#1F5AB4" && e["opacity"] == "1" && vertices(e).len() == 3)
        .count();
    assert!(marks >= 1, "no mark of the clipped estimate");
}

/// The same series drawn without the outage rule would cross it: a test of the test. A
/// series whose steps are all alike has no outage and its estimate is one line.
#[test]
fn plot_without_an_outage_draws_one_line() {
    let dir = fresh_dir("plot-no-outage");
    std::fs::write(dir.join("data.csv"), series()).unwrap();
    let out = filter_output(
        &dir,
        "f",
        &[
            "--kind", "fading", "--degree", "2", "--theta", "0.9", "--sigma", "0.5",
        ],
    );
    ok_in(&dir, &["plot", out.to_str().unwrap(), "-o", "f.svg"], "");
    let svg = svg_of(&dir.join("f.svg"));
    assert!(outage_spans(&svg).is_empty());
    assert!(!svg.contains("no samples (outage)"));
    let estimate = elements(&svg, "polyline")
        .into_iter()
        .filter(|e| e["stroke"] == "#1F5AB4" && e["stroke-width"] == "2")
        .count();
    assert_eq!(
        estimate, 3,
        "one estimate line per panel, one in the legend"
    );
    // A made-up span inside one of the estimate's segments is crossed: the check can fail.
    let line = elements(&svg, "polyline")
        .into_iter()
        .find(|e| e["stroke"] == "#1F5AB4" && vertices(e).len() > 100)
        .unwrap();
    let v = vertices(&line);
    let w = v.windows(2).find(|w| w[1].0 - w[0].0 > 2.0).unwrap();
    let inside = (w[0].0 + 0.2, w[1].0 - 0.2);
    assert!(!segments_across(&svg, &[inside]).is_empty(), "{inside:?}");
}

/// A manoeuvring series of 60,000 rows at irregular 0.01 s steps, with 8-10σ outliers on 1 %
/// of the samples and a 20 s outage, through the automatic filter and `plot`: the samples and
/// the residuals are drawn as envelopes (no dots), the outliers as at most the lowest and
/// highest small crosses per pixel column with their number in the legend (the output's count
/// of outlier flags), every curve at most four points per pixel column, no segment across the
/// outage, and the same picture from standard input as from the file.
#[test]
fn dense_automatic_output_is_legible() {
    let dir = fresh_dir("plot-dense-auto");
    let mut data = String::from("t,y\n");
    let (mut t, mut x, mut v) = (0.0f64, 0.0f64, 1.0f64);
    let mut state = 0x2545_f491_4f6c_dd1du64;
    let mut uniform = || {
        state ^= state << 13;
        state ^= state >> 7;
        state ^= state << 17;
        (state >> 11) as f64 / (1u64 << 53) as f64
    };
    let mut rows = 0;
    while rows < 60_000 {
        let h = 0.01 * (1.0 + 0.3 * (2.0 * uniform() - 1.0));
        let a = match (t / 120.0) as u32 {
            1 => 0.2,
            3 => -0.3,
            _ => 0.0,
        };
        x += v * h + 0.5 * a * h * h;
        v += a * h;
        t += h;
        let g = (-2.0 * (1.0 - uniform()).ln()).sqrt() * (std::f64::consts::TAU * uniform()).cos();
        let e = if uniform() < 0.01 {
            (if uniform() < 0.5 { -1.0 } else { 1.0 }) * (8.0 + 2.0 * uniform())
        } else {
            g
        };
        if (300.0..320.0).contains(&t) {
            continue;
        }
        data += &format!("{t},{}\n", x + e);
        rows += 1;
    }
    std::fs::write(dir.join("data.csv"), &data).unwrap();
    let out = filter_output(
        &dir,
        "auto",
        &["--kind", "auto", "--degree", "2", "--theta", "0.95"],
    );
    let text = std::fs::read_to_string(&out).unwrap();
    let header: Vec<&str> = text.lines().next().unwrap().split(',').collect();
    let col = header.iter().position(|h| *h == "outlier").unwrap();
    let flagged = text
        .lines()
        .skip(1)
        .filter(|l| l.split(',').nth(col) == Some("1"))
        .count();
    assert!(flagged > 300, "{flagged} outliers flagged");
    ok_in(
        &dir,
        &["plot", "auto.csv", "-o", "a.svg", "-o", "a.png"],
        "",
    );
    let svg = svg_of(&dir.join("a.svg"));
    assert!(
        svg.contains(&format!("rejected (outlier): {flagged}")),
        "legend count"
    );
    assert!(svg.contains("samples, lowest to highest per pixel (too dense for dots)"));
    assert!(
        count(&svg, "<circle") <= 2,
        "{} dots",
        count(&svg, "<circle")
    );
    let envelopes = elements(&svg, "polygon")
        .into_iter()
        .filter(|e| e["fill"] == "#787878")
        .count();
    assert!(
        envelopes >= 4,
        "{envelopes} envelopes (two panels, split at the outage)"
    );
    // Dense samples beyond the axis are noted by their share, not marked per column (the
    // rejected ones here, 8-10σ, are drawn as crosses at the edge).
    let marks = elements(&svg, "polygon")
        .into_iter()
        .filter(|e| e["fill"] == "#787878" && e["opacity"] == "1" && vertices(e).len() == 3)
        .count();
    assert_eq!(marks, 2, "only the legend's marks are grey triangles");
    // Small crosses, at most 4 per pixel column and panel (each cross is two lines).
    let crosses = elements(&svg, "line")
        .into_iter()
        .filter(|e| e["stroke"] == "#D7191C")
        .count()
        / 2;
    assert!(
        crosses > 100 && crosses <= 2 * 4 * 1070,
        "{crosses} crosses"
    );
    for e in elements(&svg, "polyline") {
        assert!(vertices(&e).len() <= 4 * 1070 + 8);
    }
    let spans = outage_spans(&svg);
    assert_eq!(spans.len(), 2, "{spans:?}");
    let across = segments_across(&svg, &spans);
    assert!(across.is_empty(), "drawn across the outage: {across:?}");
    // Standard input: the same picture (but the title's file name).
    ok_in(&dir, &["plot", "-", "-o", "b.svg"], &text);
    let piped = svg_of(&dir.join("b.svg")).replace("standard input", "auto.csv");
    assert!(piped == svg, "the picture from standard input differs");
    assert!(file_size(&dir.join("a.png")) > 30_000);
}
