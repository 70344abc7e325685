// Calls to runtime helpers counted by common/call_shims.S, per helper and per call site (the return
// address into the caller). The mps2-an385-calls firmware prints them per frame.
#pragma once
#include <stdint.h>

namespace fw {

constexpr int kCountedHelpers = 3;
constexpr const char* kCountedNames[kCountedHelpers] = {"__aeabi_ldivmod", "__aeabi_uldivmod", "__ctzdi2"};
constexpr int kCallSites = 64;

struct CallSite {
  uint32_t address = 0;  // return address (Thumb bit set)
  uint32_t count = 0;
};

struct CallCounts {
  uint32_t total[kCountedHelpers] = {};
  CallSite sites[kCountedHelpers][kCallSites] = {};
  uint32_t lost[kCountedHelpers] = {};  // calls from sites beyond the table
};

// Counters since the last reset.
CallCounts& call_counts();
void reset_call_counts();

}  // namespace fw
