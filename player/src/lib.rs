//! The player: draws each baked frame, already depth-sorted, with one multi-draw-indirect call.
#![deny(missing_docs)]
