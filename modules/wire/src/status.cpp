// Keeps wire_core non-empty even before any other source exists; Status itself is header-only.
#include "wire/status.hpp"
