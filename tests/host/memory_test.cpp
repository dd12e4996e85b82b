// host::populate: every page of the range made resident, in one call, the bytes kept.
#include "trajroi/host/memory.hpp"

#include <gtest/gtest.h>
#include <sys/mman.h>
#include <unistd.h>

#include <cstddef>
#include <cstdint>
#include <vector>

namespace {

struct Mapping {
  explicit Mapping(std::size_t bytes) : size(bytes) {
    data = static_cast<unsigned char*>(mmap(nullptr, size, PROT_READ | PROT_WRITE, MAP_PRIVATE | MAP_ANONYMOUS, -1, 0));
  }
  ~Mapping() {
    if (data != MAP_FAILED) munmap(data, size);
  }
  Mapping(const Mapping&) = delete;
  Mapping& operator=(const Mapping&) = delete;
  // How many of its pages are resident now (mincore).
  [[nodiscard]] std::size_t resident_pages() const {
    const auto page = static_cast<std::size_t>(sysconf(_SC_PAGESIZE));
    std::vector<unsigned char> in(size / page);
    if (mincore(data, size, in.data()) != 0) return 0;
    std::size_t n = 0;
    for (const unsigned char p : in)
      n += p & 1U;
    return n;
  }
  unsigned char* data;
  std::size_t size;
};

TEST(HostMemory, PopulateMakesEveryPageOfTheRangeResidentAndKeepsTheBytes) {
  const auto page = static_cast<std::size_t>(sysconf(_SC_PAGESIZE));
  constexpr std::size_t kPages = 64;
  Mapping m(kPages * page);
  ASSERT_NE(m.data, MAP_FAILED);
  m.data[3] = 0x5A;              // page 0
  m.data[10 * page + 7] = 0xA5;  // page 10
  EXPECT_EQ(m.resident_pages(), 2u);
  // From inside the first page to inside the last but one: every page holding a byte of it.
  trajroi::host::populate(m.data + 100, (kPages - 1) * page - 200);
  EXPECT_EQ(m.resident_pages(), kPages - 1);
  EXPECT_EQ(m.data[3], 0x5A);
  EXPECT_EQ(m.data[10 * page + 7], 0xA5);
  std::size_t nonzero = 0;
  for (std::size_t i = 0; i < kPages * page; ++i)
    nonzero += m.data[i] != 0 ? 1 : 0;
  EXPECT_EQ(nonzero, 2u);
}

TEST(HostMemory, AnEmptyRangeIsNothingToDo) {
  trajroi::host::populate(nullptr, 0);
  unsigned char byte = 7;
  trajroi::host::populate(&byte, 0);
  EXPECT_EQ(byte, 7);
}

}  // namespace
