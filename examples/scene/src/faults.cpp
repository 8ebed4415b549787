#include "faults.h"

namespace scene {

const std::vector<FaultInfo>& AllFaults() {
  static const std::vector<FaultInfo> faults = {
#define SCENE_FAULT(id, name, vuid, when, withheld, what) {FaultId::id, name, vuid, FaultWhen::when, withheld, what},
#include "faults.def"
#undef SCENE_FAULT
  };
  return faults;
}

const FaultInfo* FindFault(const std::string& name) {
  for (const FaultInfo& f : AllFaults()) {
    if (name == f.name) return &f;
  }
  return nullptr;
}

const char* WhenName(FaultWhen when) {
  switch (when) {
    case FaultWhen::kRecord: return "record";
    case FaultWhen::kSubmit: return "submit";
    case FaultWhen::kExecution: return "execution";
    case FaultWhen::kDestroy: return "destroy";
  }
  return "?";
}

void PrintFaults(std::FILE* out) {
  std::fprintf(out, "%-30s %-82s %-10s %s\n", "# fault", "VUID it must trigger", "found at", "what it does");
  for (const FaultInfo& f : AllFaults()) {
    std::fprintf(out, "%-30s %-82s %-10s %s\n", f.name, f.vuid, WhenName(f.when), f.what);
  }
}

}  // namespace scene
