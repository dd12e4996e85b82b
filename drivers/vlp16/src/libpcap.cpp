#include "libpcap.hpp"

#include <dlfcn.h>

#include <cstring>

namespace trajroi::vlp16 {
namespace {

Libpcap load() {
  Libpcap lib;
  void* handle = nullptr;
  // Debian's soname, then upstream's, then the development link.
  for (const char* name : {"libpcap.so.0.8", "libpcap.so.1", "libpcap.so"}) {
    handle = dlopen(name, RTLD_NOW | RTLD_LOCAL);
    if (handle != nullptr) break;
  }
  if (handle == nullptr) {
    const char* why = dlerror();
    lib.error = std::string(
                    "libpcap (libpcap.so.0.8), which reads captures that are not classic pcap files, "
                    "cannot be loaded: ") +
                (why != nullptr ? why : "not found");
    return lib;
  }
  const auto find = [&](auto& function, const char* name) {
    void* symbol = dlsym(handle, name);
    if (symbol == nullptr && lib.error.empty()) lib.error = std::string("libpcap has no ") + name;
    std::memcpy(&function, &symbol, sizeof function);  // an object pointer to a function pointer
  };
  find(lib.fopen_offline_with_tstamp_precision, "pcap_fopen_offline_with_tstamp_precision");
  find(lib.datalink, "pcap_datalink");
  find(lib.next_ex, "pcap_next_ex");
  find(lib.geterr, "pcap_geterr");
  find(lib.close, "pcap_close");
  return lib;  // the library stays loaded for the process
}

}  // namespace

const Libpcap& libpcap() {
  static const Libpcap lib = load();
  return lib;
}

}  // namespace trajroi::vlp16
