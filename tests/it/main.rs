//! The integration tests, built as one test binary (one link instead of one per file): each
//! module is one file of what was `tests/NAME.rs`. `tests/ordering_forced.rs` stays a binary of
//! its own, since it sets an environment variable that every solve in its process reads.

mod common;

mod adaptivity;
mod bad_battery;
mod bad_battery7;
mod bad_battery8_files;
mod bad_cli;
mod bad_data;
mod bad_edges;
mod bad_input;
mod bad_leftovers6;
mod bad_minor;
mod bad_physics;
mod bad_roles;
mod bad_settings;
mod bad_slurm;
mod bad_store;
mod bad_trust;
mod cholesky;
mod claims_criteria;
mod cli_output;
mod consistent_exact;
mod convergence;
mod doc_commands;
mod drift;
mod drift_tiers;
mod error_parts;
mod estimator;
mod estimator_repair;
mod ex72;
mod exactness;
mod fb;
mod figures;
mod gmsh;
mod gmsh_renumbered;
mod hertz;
mod kkt;
mod layers;
mod manifest;
mod parsers;
mod problem_file_forms;
mod problem_files;
mod problems;
mod record_schema;
mod report_page;
mod resume;
mod rollers;
mod scratch;
mod store;
mod stress_frame;
mod study;
mod study_names;
mod verdicts;
