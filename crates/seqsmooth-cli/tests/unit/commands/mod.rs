//! Unit tests of `commands`: one module per subcommand, and `shared`.

mod demo;
mod plot;
mod shared;
