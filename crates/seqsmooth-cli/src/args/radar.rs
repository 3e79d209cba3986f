//! The radar arguments that `seqsmooth track` and `seqsmooth fit` share: the site, the azimuth
//! convention and each component's noise σ (a flag, or a column).

use super::{parse_sigma, refused};
use clap::builder::{PossibleValuesParser, TypedValueParser};
use clap::Args;
use seqsmooth::model::radar::{check_site, AzimuthConvention};

/// The radar input of `seqsmooth track` and `seqsmooth fit --model radar`, read by one reader
/// (`track::rows`) and checked by the library's rule for a radar row
/// (`seqsmooth::model::radar::check_component`).
#[derive(Debug, Args)]
pub struct RadarArgs {
    /// Radar: the site's position X,Y,Z in the units of the range
    #[arg(long, value_name = "X,Y,Z", default_value = "0,0,0", value_parser = parse_site,
          allow_hyphen_values = true)]
    pub site: [f64; 3],
    /// Radar: the range's noise standard deviation (this or --sigma-range-col is required)
    #[arg(long, value_name = "S", value_parser = parse_sigma, allow_hyphen_values = true)]
    pub sigma_range: Option<f64>,
    /// Radar: the azimuth's and elevation's noise standard deviation in radians (this or
    /// --sigma-angle-col is required)
    #[arg(long, value_name = "S", value_parser = parse_sigma, allow_hyphen_values = true)]
    pub sigma_angle: Option<f64>,
    /// Radar: name of a column of per-row range sigmas; an empty cell takes --sigma-range
    #[arg(long, value_name = "NAME")]
    pub sigma_range_col: Option<String>,
    /// Radar: name of a column of per-row angle sigmas (azimuth and elevation, radians); an
    /// empty cell takes --sigma-angle
    #[arg(long, value_name = "NAME")]
    pub sigma_angle_col: Option<String>,
    /// Radar: how the input's azimuths are measured: from +x towards +y, or as a bearing
    /// (clockwise from north, with x = east and y = north)
    #[arg(long, value_name = "AZIMUTH", default_value_t = AzimuthConvention::default(),
          value_parser = azimuth_parser())]
    pub azimuth: AzimuthConvention,
    /// Radar: name of the range column
    #[arg(long, value_name = "NAME", default_value = "range")]
    pub range_col: String,
    /// Radar: name of the azimuth column
    #[arg(long, value_name = "NAME", default_value = "azimuth")]
    pub azimuth_col: String,
    /// Radar: name of the elevation column
    #[arg(long, value_name = "NAME", default_value = "elevation")]
    pub elevation_col: String,
}

/// Parses `--azimuth`: one of the library's names of a convention
/// ([`AzimuthConvention::from_name`]), listed in `--help`.
pub fn azimuth_parser() -> impl TypedValueParser<Value = AzimuthConvention> {
    PossibleValuesParser::new(AzimuthConvention::NAMES)
        .try_map(|name| AzimuthConvention::from_name(&name).map_err(refused))
}

/// Parses `--site`: three finite numbers `X,Y,Z`.
pub fn parse_site(s: &str) -> Result<[f64; 3], String> {
    let parts: Vec<&str> = s.split(',').map(str::trim).collect();
    let [x, y, z] = parts[..] else {
        return Err(format!(
            "site '{}' must be three numbers X,Y,Z separated by commas",
            s.trim()
        ));
    };
    let mut site = [0.0; 3];
    for (slot, (axis, text)) in site.iter_mut().zip([("X", x), ("Y", y), ("Z", z)]) {
        *slot = text
            .parse::<f64>()
            .map_err(|_| format!("site {axis} '{text}' is not a number"))?;
    }
    // The library's range of a site.
    check_site(site).map_err(refused)?;
    Ok(site)
}
