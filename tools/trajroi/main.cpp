// trajroi: the command-line tool of the trajroi project (evaluation, filtering, dumps).
#include <cstdio>
#include <exception>
#include <string>

#include "commands.hpp"

int main(int argc, char** argv) {
  CLI::App app{"trajroi — trajectory-based regions of interest for LiDAR point clouds"};
  app.set_version_flag("--version", std::string("trajroi ") + TRAJROI_VERSION);
  app.require_subcommand(1);
  trajroi::cli::add_eval_commands(app);
  trajroi::cli::add_filter_command(app);
  trajroi::cli::add_lidar_dump_command(app);
  trajroi::cli::add_serial_dump_commands(app);
  trajroi::cli::add_sim_command(app);
  trajroi::cli::add_render_command(app);
  trajroi::cli::add_watch_command(app);
  trajroi::cli::add_feed_command(app);
  trajroi::cli::add_configure_command(app);
  trajroi::cli::add_machine_command(app);
  trajroi::cli::add_export_command(app);
  trajroi::cli::add_view_command(app);
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return app.exit(e);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "trajroi: error: %s\n", e.what());
    return 1;
  }
  return 0;
}
