// mjcffi's C helper: code that must run natively, beside the cffi wrappers.
// Compiled into mjcffi._mjcffi by mjcffi/_build.py; declared in _helper.h.

#include <mujoco/mujoco.h>

#include "_helper.h"

// The import-time check compares this with mj_version(): the header version
// is baked in when the module is compiled, the library version when loaded.
int mjcffi_header_version(void) {
  return mjVERSION_HEADER;
}
