//! The ORDER file (docs/FORMAT.md § ORDER): the format ([`trisort_format::order`]),
//! re-exported. Building one needs the glTF importer, so it lives in trisort-capi-export
//! (`libtrisort_export`), not in the player library.

pub use trisort_format::order::{
    Order, OrderError, OrderRange, OrderSource, ORDER_MAGIC, ORDER_VERSION,
};
