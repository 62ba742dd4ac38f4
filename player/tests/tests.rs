//! The player's integration tests, one binary: the baked file as the player reads it
//! (`baked_file`, no GPU), what it draws (`play`), how it shades (`shading`; the frame its
//! normal maps are read in: `tangent_frame`; its block-compressed textures:
//! `texture_blocks`) and its WebGL2 tier (`tiers`).

mod support;

mod baked_file;
mod clips;
mod play;
mod self_check;
mod shading;
mod tangent_frame;
mod texture_blocks;
mod tiers;
mod variants;
