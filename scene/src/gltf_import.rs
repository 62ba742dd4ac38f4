//! glTF 2.0 import.
