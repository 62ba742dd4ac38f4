//! The recorder's integration tests, one binary: known answers on scenes built here
//! (`known_answers`), robust recording (`robust`), a 5-million-triangle scene (`scale`) and
//! the compact readback against the former one (`compact_readback`), the one-pass fragment
//! capture against depth peeling (`capture`), and the visibility-only
//! texture upload against the full one (`visibility_upload`).

mod capture;
mod compact_readback;
mod known_answers;
mod robust;
mod scale;
mod visibility_upload;
