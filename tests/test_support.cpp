#include "test_support.h"

namespace lodforge::test {

const char* sharedDataDir() {
  return LODFORGE_DATA_DIR;
}
const char* testDataDir() {
  return LODFORGE_TEST_DATA_DIR;
}

}  // namespace lodforge::test
