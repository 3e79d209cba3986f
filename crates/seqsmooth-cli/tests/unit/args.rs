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
    assert!(parse_degree("25").unwrap_err().contains("degree 25"));
    assert!(parse_degree("-1").unwrap_err().contains("degree -1"));
    assert!(parse_degree("x").is_err());
}

#[test]
fn window_range() {
    assert_eq!(parse_window("1"), Ok(1));
    assert_eq!(parse_window(" 11 "), Ok(11));
    assert!(parse_window("0")
        .unwrap_err()
        .contains("window 0 is out of range"));
    assert!(parse_window("-3").unwrap_err().contains("window -3"));
    assert!(parse_window("2.5").is_err());
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
    assert!(parse_lead_steps("1e-99999999")
        .unwrap_err()
        .contains("out of range"));
    assert!(parse_lead_steps("inf").is_err());
}
