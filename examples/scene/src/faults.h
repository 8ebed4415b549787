#pragma once
// The rule violations the scene can commit on request (--inject), one per rule family asval checks.
#include <cstdio>
#include <string>
#include <vector>

namespace scene {

enum class FaultId {
#define SCENE_FAULT(id, name, vuid, when, withheld, what) id,
#include "faults.def"
#undef SCENE_FAULT
};

enum class FaultWhen { kRecord, kSubmit, kExecution, kDestroy };

struct FaultInfo {
  FaultId id;
  const char* name;
  const char* vuid;
  FaultWhen when;
  bool withheld;  // see faults.def
  const char* what;
};

const std::vector<FaultInfo>& AllFaults();
const FaultInfo* FindFault(const std::string& name);
const char* WhenName(FaultWhen when);
// One line per fault: name, VUID, when, what.
void PrintFaults(std::FILE* out);

}  // namespace scene
