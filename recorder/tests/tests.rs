//! The recorder's integration tests, one binary: known answers on scenes built here
//! (`known_answers`), robust recording (`robust`) and a 5-million-triangle scene (`scale`).

mod known_answers;
mod robust;
mod scale;
