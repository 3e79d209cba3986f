//! The drawing of a filter's run, for `seqsmooth plot` and `seqsmooth demo`: the chart
//! ([`chart`], PNG or SVG: its panels, and the rows of a run and the rules that read them),
//! per-pixel decimation of dense series ([`decimate`]) and short tick labels ([`ticks`]).

pub mod chart;
pub mod decimate;
pub mod ticks;
