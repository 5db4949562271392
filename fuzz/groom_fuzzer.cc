// libFuzzer target: groom (fuzz/readers.h, docs/fuzzing.md).
#include "readers.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  return flexkin::fuzz::RunOne(flexkin::fuzz::ReadGroomScenario, data, size);
}
