//! Unit tests of `args`: the clap definition and the parsers of the numeric arguments.

use clap::CommandFactory;
use seqsmooth_cli::args::*;

#[test]
fn clap_definition_is_consistent() {
    Cli::command().debug_assert();
}

#[test]
fn theta_forms() {
    assert_eq!(parse_theta("9/10").unwrap().exact.to_string(), "9/10");
    assert_eq!(parse_theta("0.9").unwrap().exact.to_string(), "9/10");
    assert_eq!(parse_theta("0.9").unwrap().value, 0.9);
    assert!(parse_theta("1").is_err());
    assert!(parse_theta("0").is_err());
    assert!(parse_theta("nan").is_err());
    let near_one = parse_theta("0.99999999999999999999").unwrap();
    assert!(near_one.value_f64().is_err());
}

#[test]
fn degree_range() {
    assert_eq!(parse_degree("0"), Ok(0));
    assert_eq!(parse_degree("24"), Ok(24));
    assert_eq!(
        parse_degree("25").unwrap_err(),
        "--degree 25 is out of range: the largest supported degree is 24"
    );
    assert_eq!(
        parse_degree("-1").unwrap_err(),
        "degree -1 is out of range: it must be a whole number from 0 to 24"
    );
    assert!(parse_degree("x").is_err());
}

/// Every range the parsers apply is the library's: its check refuses, in the command's words
/// (the flag), and the bounds the messages quote are its constants.
#[test]
fn ranges_are_the_librarys() {
    use seqsmooth::estimate::gauss_newton::MAX_ITERATIONS;
    use seqsmooth::model::radar::AzimuthConvention;
    use seqsmooth::polynomial::MAX_DEGREE;
    assert_eq!(parse_derivative(&MAX_DEGREE.to_string()), Ok(MAX_DEGREE));
    assert_eq!(
        parse_derivative("25").unwrap_err(),
        "--derivative 25 is invalid: at most 24, the largest supported degree"
    );
    assert_eq!(parse_lead("-2.5"), Ok(-2.5));
    assert_eq!(
        parse_lead("inf").unwrap_err(),
        "--lead inf is invalid: must be a finite number"
    );
    assert_eq!(parse_lead("x").unwrap_err(), "lead 'x' is not a number");
    assert_eq!(
        parse_max_iterations(&MAX_ITERATIONS.to_string()),
        Ok(MAX_ITERATIONS)
    );
    for (text, shown) in [("0", "0"), ("1001", "1001"), ("-5", "-5")] {
        assert_eq!(
            parse_max_iterations(text).unwrap_err(),
            format!("--max-iterations {shown} is invalid: must be from 1 to 1000")
        );
    }
    assert_eq!(parse_psd("0"), Ok(0.0));
    assert_eq!(
        parse_psd("-1").unwrap_err(),
        "--q -1 is invalid: must be a finite number at least 0"
    );
    assert_eq!(parse_segment("2.5"), Ok(2.5));
    assert_eq!(
        parse_segment("0").unwrap_err(),
        "--segment 0 is invalid: must be a positive finite number"
    );
    assert_eq!(parse_paml_degree("30"), Ok(30));
    assert_eq!(
        parse_paml_degree("31").unwrap_err(),
        "--degree 31 is out of range: the largest supported degree is 30"
    );
    assert_eq!(parse_index("18446744073709551615"), Ok(u64::MAX));
    assert_eq!(
        parse_index("-1").unwrap_err(),
        "n '-1' is not a whole number (0, 1, 2, ...)"
    );
    assert_eq!(
        parse_epoch("center"),
        Ok(seqsmooth::estimate::gauss_newton::Epoch::Centre)
    );
    assert_eq!(
        parse_epoch("inf").unwrap_err(),
        "--epoch inf is invalid: must be 'end', 'centre' or a finite time"
    );
    assert_eq!(
        parse_epoch("x").unwrap_err(),
        "epoch 'x' is neither 'end', 'centre' nor a time"
    );
    assert_eq!(
        parse_site("1,inf,2").unwrap_err(),
        "--site inf is invalid: a radar site's coordinates must be finite"
    );
    let azimuth = |s: &str| {
        let cmd = clap::Command::new("t").arg(
            clap::Arg::new("azimuth")
                .long("azimuth")
                .value_parser(azimuth_parser()),
        );
        cmd.try_get_matches_from(["t", "--azimuth", s])
            .map(|m| *m.get_one::<AzimuthConvention>("azimuth").unwrap())
    };
    assert_eq!(azimuth("bearing").unwrap(), AzimuthConvention::Bearing);
    assert_eq!(azimuth("from-x").unwrap(), AzimuthConvention::FromX);
    assert!(azimuth("north").is_err());
}

#[test]
fn window_range() {
    assert_eq!(parse_window("1"), Ok(1));
    assert_eq!(parse_window(" 11 "), Ok(11));
    assert_eq!(
        parse_window("0").unwrap_err(),
        "--window 0 is invalid: must hold at least 1 sample"
    );
    // A negative window by the library's rule of the smallest, named as given.
    assert_eq!(
        parse_window("-3").unwrap_err(),
        "--window -3 is invalid: must hold at least 1 sample"
    );
    assert_eq!(
        parse_window("2.5").unwrap_err(),
        "window '2.5' is not a whole number of samples"
    );
}

#[test]
fn lead_steps_forms() {
    assert_eq!(parse_lead_steps("-5/2").unwrap().exact.to_string(), "-5/2");
    assert_eq!(parse_lead_steps("-2.5").unwrap().exact.to_string(), "-5/2");
    assert_eq!(parse_lead_steps("25e-1").unwrap().value, 2.5);
    assert_eq!(parse_lead_steps("0").unwrap().value, 0.0);
    assert!(parse_lead_steps("x")
        .unwrap_err()
        .contains("lead 'x' is not a number"));
    assert!(parse_lead_steps("1e999")
        .unwrap_err()
        .contains("out of range"));
    assert_eq!(
        parse_lead_steps("1e399").unwrap_err(),
        "--lead inf is invalid: must be a finite number of samples, |H| < 1e300"
    );
    assert!(parse_lead_steps("-1e300").is_err() && parse_lead_steps("-9.9e299").is_ok());
    assert!(parse_lead_steps("1e-99999999")
        .unwrap_err()
        .contains("out of range"));
    assert!(parse_lead_steps("inf").is_err());
}
