// trajroi's point clouds in C++, printed as they arrive (examples/CMakeLists.txt builds it).
#include <cstdio>
#include <lcm/lcm-cpp.hpp>
#include <trajroi/points_t.hpp>

struct Printer {
  void on_points(const lcm::ReceiveBuffer*, const std::string&, const trajroi::points_t* m) {
    std::printf("sweep %lld: %d of %d points kept, pose %s\n", static_cast<long long>(m->sweep_index), m->num_points,
                m->points_in, m->pose.valid ? "valid" : "invalid");
    std::fflush(stdout);
  }
};

int main(int argc, char** argv) {
  lcm::LCM lcm(argc > 1 ? argv[1] : "udpm://239.255.76.67:7667?ttl=0&recv_buf_size=8388608");
  Printer printer;
  lcm.subscribe("TRAJROI_POINTS", &Printer::on_points, &printer);
  while (lcm.handle() == 0)
    continue;
}
