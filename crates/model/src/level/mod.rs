//! What a level of the adaptive loop leaves behind: its record ([`record::LevelRecord`], the
//! one record type a study stores per level), the estimator's terms ([`terms::Terms`]), the
//! contact samples of its solution ([`sample::ContactSample`]) and the marks that rebuild its
//! mesh ([`history`]).

pub mod history;
pub mod record;
pub mod sample;
pub mod terms;
