// `sdfc mesh`: placeholder until the mesher lands (mesh/).
#include <iostream>

#include "commands.h"

namespace sdfc {
int runMesh(const CommandLine&) {
  std::cerr << "sdfc: error: mesh export is not built yet\n";
  return kExitUsage;
}
}  // namespace sdfc
