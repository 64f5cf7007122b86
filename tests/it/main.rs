//! aloft's integration tests, one binary: a module per area (each was its own test binary, and
//! linked the whole crate; one link instead of 62). `cargo test --test it NAME::` runs one area,
//! e.g. `cargo test --test it serve_hostile::`. `common` holds the helpers they share. One test
//! keeps a binary of its own: `tests/power_streaming.rs` measures its own process's peak memory,
//! which other tests running beside it in one process would raise.

mod common;

mod air_cli;
mod build_profiles;
mod cli_ffi;
mod cli_power;
mod disclosure;
mod doc_commands;
mod engine_cli;
mod examples;
mod fit_quality_data_val;
mod identify_data_val;
mod input_contract;
mod kaist_failsafe_data_val;
mod kaist_lodo_data_val;
mod live_evidence;
mod live_interrupt;
mod live_loopback;
mod live_px4_data_val;
mod live_replay_events_data_val;
mod live_soc_data_val;
mod live_tlog_data_val;
mod live_tlog_hostile;
mod live_udp_reply;
mod logbook_cli;
mod logs_binary_cli;
mod logs_binary_data_val;
mod logs_binary_hostile;
mod logs_cli;
mod logs_convert_data_val;
mod logs_data_val;
mod logs_hostile_inputs;
mod logs_mcap;
mod logs_read;
mod mission_loiter_sorties;
mod missions_data_val;
mod missions_writers;
mod one_mass;
mod outputs_hostile;
mod own_vehicle_data_val;
mod pack_state_cli;
mod pack_voltage_data_val;
mod packs_cli;
mod payload_sweep;
mod plan_cli;
mod plan_confidence;
mod plan_files_data_val;
mod planner_checks;
mod planner_cli;
mod planner_envelope;
mod power_paper_val;
mod propulsion_data_val;
mod propulsion_paper_val;
mod replay_data_val;
mod replay_ground;
mod replay_ground_data_val;
mod scenarios;
mod scenarios_cli;
mod serve;
mod serve_browser;
mod serve_hold;
mod serve_hostile;
mod serve_plan;
mod terrain_cli;
mod terrain_map;
mod terrain_mission;
mod vehicle_file_doc;
mod vehicles_cli;
mod vehicles_paper_val;
