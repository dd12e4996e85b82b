#pragma once

#include <CLI/CLI.hpp>

namespace trajroi::cli {

// Each adds one subcommand (with its options and its callback) to the application.
void add_eval_commands(CLI::App& app);
void add_filter_command(CLI::App& app);
void add_lidar_dump_command(CLI::App& app);
void add_serial_dump_commands(CLI::App& app);  // gnss-dump, imu-dump
void add_sim_command(CLI::App& app);
void add_render_command(CLI::App& app);
void add_watch_command(CLI::App& app);      // listens to trajroid over LCM
void add_configure_command(CLI::App& app);  // trajroi configure gnss|imu
void add_feed_command(CLI::App& app);       // plays a run folder into a live trajroid
void add_machine_command(CLI::App& app);    // how steadily this machine gives a thread its CPU
void add_export_command(CLI::App& app);     // kept points from an LCM log as PCD / PLY files
void add_view_command(CLI::App& app);       // a live view in the browser
// keyframes, sequential, accumulated under `eval`.
void add_scenario_eval_commands(CLI::App& eval_cmd);

}  // namespace trajroi::cli
