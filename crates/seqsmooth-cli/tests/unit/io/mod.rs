//! Unit tests of `io`: CSV line numbers, number cells and round-trip number output.

mod rows;

use seqsmooth_cli::io::*;

fn lines(text: &str) -> Vec<u64> {
    let mut r = CsvIn::new(text.as_bytes()).unwrap();
    let mut v = Vec::new();
    while r.next_record().unwrap() {
        v.push(r.line);
    }
    v
}

#[test]
fn line_numbers_survive_blank_lines_crlf_and_quotes() {
    assert_eq!(lines("t,y\n\n\n0,1\n1,2\n"), [4, 5]);
    assert_eq!(lines("\nt,y\n0,1\n"), [3]);
    assert_eq!(lines("t,y\r\n0,1\r\n\r\n1,2\r\n"), [2, 4]);
    assert_eq!(lines("t,y\n0,1\r\n1,2\r2,3\n\r\n4,5"), [2, 3, 4, 6]);
    assert_eq!(lines("t,y,z\n0,1,\"a\nb\"\n1,2,x\n"), [2, 4]);
    assert_eq!(lines("t,y\n0,1\n\n\n\n1,2\n"), [2, 6]);
    // Breaks are counted in chunks of 255 bytes: quoted cells longer than that, LF and CRLF.
    let long_lf = format!("t,y,z\n0,1,\"{}\"\n1,2,x\n", "\n".repeat(600));
    assert_eq!(lines(&long_lf), [2, 603]);
    let long_crlf = format!("t,y,z\r\n0,1,\"{}\"\r\n1,2,x\r\n", "a\r\n".repeat(300));
    assert_eq!(lines(&long_crlf), [2, 303]);
}

#[test]
fn line_numbers_across_buffer_refills() {
    let mut text = String::from("t,y\r\n");
    let mut want = Vec::new();
    let mut line = 1;
    for k in 0..5000 {
        text += &format!("{k},{k}\r\n");
        line += 1;
        want.push(line);
        if k % 7 == 0 {
            text += "\r\n";
            line += 1;
        }
    }
    assert_eq!(lines(&text), want);
}

#[test]
fn reader_lines_and_messages() {
    let mut r = CsvIn::new("t,y\n0,1\n1,2\n\n2,abc\n".as_bytes()).unwrap();
    let mut cells = Vec::new();
    while r.next_record().unwrap() {
        cells.push(parse_cell(r.field(1), r.line, "y", "value").map_err(|e| e.to_string()));
    }
    assert_eq!(cells[..2], [Ok(1.0), Ok(2.0)]);
    assert_eq!(
        cells[2],
        Err("line 5, column 'y': 'abc' is not a number".into())
    );
}

/// Every cell parses to the double `str::parse` gives, and is refused where it refuses.
#[test]
fn cells_parse_as_str_parse() {
    for text in [
        "0",
        "-0",
        "1",
        "+7",
        ".5",
        "8.",
        "1e5",
        "1E+5",
        "2.5e-300",
        "1e-400",
        "1e400",
        "inf",
        "-Infinity",
        "NaN",
        "nan",
        "1e",
        "e5",
        ".",
        "+",
        "-",
        "1.2.3",
        "0x10",
        "1_0",
        "1,5",
        "4.9406564584124654e-324",
        "17976931348623157e292",
        "0.1000000000000000055511151231",
        "9007199254740993",
        "1.",
        "+.5e1",
        "  1",
        "1d",
        "١",
    ] {
        let std = text.parse::<f64>().ok().filter(|v| v.is_finite());
        let ours = parse_cell(text.as_bytes(), 1, "y", "value").ok();
        assert_eq!(ours.map(f64::to_bits), std.map(f64::to_bits), "{text:?}");
    }
}

fn check(x: f64) {
    let s = fmt_f64(x);
    let back: f64 = s.parse().unwrap();
    assert_eq!(back.to_bits(), x.to_bits(), "{x:?} printed as {s}");
    assert!(s.len() <= 24, "{x:?} printed as {s} ({} chars)", s.len());
    // Rust's layout: `{}` for 1e-5 <= |x| < 1e16 and zero, `{:e}` otherwise.
    let std = if x == 0.0 || (1e-5..1e16).contains(&x.abs()) {
        format!("{x}")
    } else {
        format!("{x:e}")
    };
    assert_eq!(s, std);
}

#[test]
fn round_trip_special_values() {
    for x in [
        0.0,
        -0.0,
        1.0,
        -1.0,
        0.1,
        0.1 + 0.2,
        1e-5,
        9.999999999999999e-6,
        1e16,
        9999999999999998.0,
        1e-300,
        -1e-300,
        5e-324,
        f64::MIN_POSITIVE,
        f64::MAX,
        f64::MIN,
        f64::EPSILON,
        123456.789,
        2.5e20,
        1e15,
        100.0,
    ] {
        check(x);
    }
    assert_eq!(fmt_f64(1e-300), "1e-300");
    // Zero and negative zero: no lowest set bit (a shift by 64 panicked with overflow checks).
    assert_eq!(fmt_f64(0.0), "0");
    assert_eq!(fmt_f64(-0.0), "-0");
    assert_eq!(fmt_f64(2.5e20), "2.5e20");
    assert_eq!(fmt_f64(0.1), "0.1");
    assert_eq!(fmt_f64(4.6), "4.6");
    assert_eq!(fmt_f64(3.0), "3");
}

#[test]
fn round_trip_many_bit_patterns() {
    // xorshift64 over all exponents: every finite double must survive.
    let mut state = 0x9E37_79B9_7F4A_7C15_u64;
    for _ in 0..200_000 {
        state ^= state << 13;
        state ^= state >> 7;
        state ^= state << 17;
        let x = f64::from_bits(state);
        if x.is_finite() {
            check(x);
        }
    }
}

#[test]
fn csv_fields_are_quoted_where_needed() {
    assert_eq!(csv_field(b"abc"), b"abc");
    assert_eq!(csv_field(b"a,b"), b"\"a,b\"");
    assert_eq!(csv_field(b"say \"hi\""), b"\"say \"\"hi\"\"\"");
    assert_eq!(csv_field(b"a\nb"), b"\"a\nb\"");
}

#[test]
fn messages_quote_cells_short_and_visible() {
    // Short text as it is; invisible characters escaped; long text cut with its length.
    assert_eq!(shown(b"abc"), "abc");
    assert_eq!(shown("é ü".as_bytes()), "é ü");
    assert_eq!(shown(b"1\x002"), "1\\02");
    assert_eq!(shown(b"\t1\r"), "\\t1\\r");
    assert_eq!(
        shown("a\u{200b}b\u{feff}".as_bytes()),
        "a\\u{200b}b\\u{feff}"
    );
    assert_eq!(shown(&[0xff, b'1']), "\u{fffd}1");
    let long = vec![b'7'; 10_000_000];
    let s = shown(&long);
    assert_eq!(s, format!("{}… (10000000 bytes)", "7".repeat(40)));
    assert_eq!(shown(&[b'x'; 64]), "x".repeat(64));
    assert_eq!(
        shown(&[b'x'; 65]),
        format!("{}… (65 bytes)", "x".repeat(40))
    );
}
