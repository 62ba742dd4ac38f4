//! The independent validator: checks a Baked file against its Recording using only the file formats.
#![deny(missing_docs)]
