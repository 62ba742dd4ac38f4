//! The player's integration tests, one binary: the baked file as the player reads it
//! (`baked_file`, no GPU), what it draws (`play`), how it shades (`shading`) and its WebGL2
//! tier (`tiers`).

mod support;

mod baked_file;
mod play;
mod self_check;
mod shading;
mod tiers;
mod variants;
