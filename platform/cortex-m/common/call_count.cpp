#include "platform/cortex-m/common/call_count.h"

namespace fw {
namespace {
CallCounts g_counts;
}

CallCounts& call_counts() { return g_counts; }

void reset_call_counts() { g_counts = CallCounts(); }

}  // namespace fw

extern "C" void fw_count_call(uint32_t which, uint32_t return_address) {
  if (which >= uint32_t(fw::kCountedHelpers)) return;
  fw::CallCounts& c = fw::call_counts();
  ++c.total[which];
  for (fw::CallSite& s : c.sites[which]) {
    if (s.address == return_address || s.address == 0) {
      s.address = return_address;
      ++s.count;
      return;
    }
  }
  ++c.lost[which];
}
