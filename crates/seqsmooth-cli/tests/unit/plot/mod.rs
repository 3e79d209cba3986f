//! Unit tests of `plot`: the chart, decimation and tick labels.

mod chart;
mod decimate;
mod ticks;
