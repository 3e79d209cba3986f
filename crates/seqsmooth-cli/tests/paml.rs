//! End-to-end tests of `seqsmooth paml`: each segment's rows are the library's
//! `PolynomialSamples` of that segment bit for bit (constant σ and a σ column), segments from
//! the first sample's time, a short segment named on standard error and left out, and the
//! refusals with line and column.

use seqsmooth::paml::PolynomialSamples;

mod common;
use common::*;

/// 200 rows from 1.7e9, 0.05 apart with a gap, values on a curve, σ cycling.
fn series() -> (String, Vec<(f64, f64, f64)>) {
    let mut text = String::from("t,y,noise\n");
    let mut rows = Vec::new();
    for k in 0..200u32 {
        let gap = if k >= 120 { 3.0 } else { 0.0 }; // segment 3 (t0 + 6..8) gets no samples
        let t = 1.7e9 + f64::from(k) * 0.05 + gap;
        let y = (f64::from(k) * 0.1).sin() * 4.0 + f64::from(k % 5) * 0.1;
        let s = 0.2 + f64::from(k % 3) * 0.1;
        text += &format!("{t},{y},{s}\n");
        rows.push((t, y, s));
    }
    (text, rows)
}

fn expected(rows: &[(f64, f64, f64)], segment: f64, order: usize, sigma: Option<f64>) -> String {
    let t0 = rows[0].0;
    let mut out = String::from("segment,t,value,variance\n");
    let mut k = 0;
    while k < rows.len() {
        let index = ((rows[k].0 - t0) / segment).floor() as u64;
        let mut end = k;
        while end < rows.len() && ((rows[end].0 - t0) / segment).floor() as u64 == index {
            end += 1;
        }
        let part = &rows[k..end];
        if part.len() > order {
            let t: Vec<f64> = part.iter().map(|r| r.0).collect();
            let y: Vec<f64> = part.iter().map(|r| r.1).collect();
            let s: Vec<f64> = part.iter().map(|r| sigma.unwrap_or(r.2)).collect();
            let ps = PolynomialSamples::from_segment(&t, &y, &s, order).unwrap();
            for ((t, v), var) in ps.times().iter().zip(&ps.values).zip(&ps.variances) {
                out += &format!("{index},{t:?},{v:?},{var:?}\n");
            }
        }
        k = end;
    }
    out
}

#[test]
fn segments_are_the_librarys_polynomial_samples() {
    let (text, rows) = series();
    for (segment, order) in [(2.0, 3usize), (5.0, 5), (1.0, 0)] {
        let got = ok(
            &[
                "paml",
                "--degree",
                &order.to_string(),
                "--segment",
                &segment.to_string(),
                "--sigma-col",
                "noise",
            ],
            &text,
        );
        assert_eq!(
            got,
            expected(&rows, segment, order, None),
            "segment {segment} order {order}"
        );
        let got = ok(
            &[
                "paml",
                "--degree",
                &order.to_string(),
                "--segment",
                &segment.to_string(),
                "--sigma",
                "0.5",
            ],
            &text,
        );
        assert_eq!(got, expected(&rows, segment, order, Some(0.5)));
    }
    // no sigma: unit noise
    let got = ok(&["paml", "--order", "2", "--segment", "2"], &text); // the paper's word, an alias
    assert_eq!(got, expected(&rows, 2.0, 2, Some(1.0)));
    // the gap: segment 3 is empty, the numbering keeps time
    assert!(got.contains("\n2,") && !got.contains("\n3,") && got.contains("\n4,"));
}

#[test]
fn a_short_segment_is_named_and_left_out() {
    let text = "t,y\n0,1\n0.5,2\n1,3\n1.5,4\n10,5\n10.5,6\n";
    let o = run(&["paml", "--degree", "2", "--segment", "5"], text);
    assert_eq!(o.code, 0, "{}", o.stderr);
    assert!(
        o.stderr
            .contains("segment 2 [10, 15) has 2 samples, degree 2 needs 3: left out"),
        "{}",
        o.stderr
    );
    let (header, rows) = table(&o.stdout);
    assert_eq!(header, ["segment", "t", "value", "variance"]);
    assert_eq!(rows.len(), 3);
    assert!(rows.iter().all(|r| r[0] == "0"));
}

#[test]
fn bad_input_is_refused_with_its_place() {
    fails(
        &["paml", "--degree", "2", "--segment", "0"],
        "t,y\n",
        2,
        &["error: invalid value '0' for '--segment <SECONDS>': --segment 0 is invalid: must be a \
           positive finite number\n"],
    );
    fails(
        &["paml", "--degree", "31", "--segment", "1"],
        "t,y\n",
        2,
        &["error: invalid value '31' for '--degree <N>': --degree 31 is out of range: the largest \
           supported degree is 30\n"],
    );
    fails(
        &["paml", "--degree", "1", "--segment", "1", "--sigma", "-1"],
        "t,y\n",
        2,
        &["sigma"],
    );
    fails(
        &[
            "paml",
            "--degree",
            "1",
            "--segment",
            "1",
            "--sigma",
            "1",
            "--sigma-col",
            "s",
        ],
        "t,y,s\n",
        2,
        &["cannot be used with"],
    );
    fails(
        &["paml", "--degree", "1", "--segment", "1"],
        "t,y\n0,1\n1,nan\n",
        1,
        &["line 3"],
    );
    fails(
        &["paml", "--degree", "1", "--segment", "10"],
        "t,y\n0,1\n2,1\n1,1\n",
        1,
        &["line 4", "not after"],
    );
    fails(
        &[
            "paml",
            "--degree",
            "1",
            "--segment",
            "10",
            "--sigma-col",
            "s",
        ],
        "t,y,s\n0,1,1\n1,2,0\n",
        1,
        &["line 3", "noise sigma 0"],
    );
    fails(
        &[
            "paml",
            "--degree",
            "1",
            "--segment",
            "1",
            "--sigma-col",
            "s",
        ],
        "t,y\n0,1\n",
        1,
        &["'s'"],
    );
    fails(
        &["paml", "--degree", "3", "--segment", "10"],
        "t,y\n0,1\n1,2\n",
        1,
        &["degree 3", "4"],
    );
}
