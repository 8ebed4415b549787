#pragma once
// One walk over the geometries of a device build, for every family that has per-geometry rules: per geometry,
// the facts every family needs (the geometry, its vertex-format row, its index size, its range) are looked up
// once and each enabled family's rules run over them with a ScreeningJudge (rule_judge.h). An info in which a
// family's rules find nothing (the common case: a valid build) is not walked by that family again; the others
// are flagged in ResolvedInfo::walks and walked by the family itself, which then reports and counts exactly as
// a walk over every info would. Host builds, infos whose geometries cannot be walked and null geometries are not
// screened: every family walks them as before.
#include <cstdint>

#include "buffer_memo.h"
#include "build_command.h"
#include "check_context.h"
#include "resolved_build.h"

namespace asval {

// Sets r.walks for pInfos[i]. memo: this call's buffer memo (synced), or null when the addresses family is off.
void ScreenGeometries(const CheckContext& ctx, const BuildCommand& cmd, uint32_t i, BufferMemo* memo, ResolvedInfo& r);

}  // namespace asval
