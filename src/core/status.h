// Errors are values. A Status carries a code, a short static message and, where it helps the user,
// one number (for ArenaTooSmall: the bytes needed). Host tools turn it into a one-line message.
#pragma once
#include <stdint.h>

namespace ml {

enum class StatusCode : uint8_t {
  Ok = 0,
  InvalidArgument,   // bad size, bad camera, bad option
  ArenaTooSmall,     // value = bytes needed
  BadScene,          // blob failed validation; message says which check
  Unsupported,       // valid input maskline cannot draw (e.g. screen larger than kMaxScreenDim)
  SinkFailed,        // the display or file refused a write
};

struct Status {
  StatusCode code = StatusCode::Ok;
  const char* message = "ok";
  uint64_t value = 0;

  bool ok() const { return code == StatusCode::Ok; }
};

inline Status ok_status() { return Status{}; }
inline Status error(StatusCode code, const char* message, uint64_t value = 0) {
  return Status{code, message, value};
}

}  // namespace ml
