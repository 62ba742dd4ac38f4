//! The player's integration tests, one binary: the baked file as the player reads it
//! (`baked_file`, no GPU) and what it draws (`play`).

mod support;

mod baked_file;
mod play;
