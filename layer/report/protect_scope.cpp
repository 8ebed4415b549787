#include "protect_scope.h"

namespace asval {

namespace {
thread_local ProtectScope* t_current = nullptr;
}  // namespace

ProtectScope::ProtectScope(bool active) : active_(active) {
  if (!active_) return;
  outer_ = t_current;
  t_current = this;
}

ProtectScope::~ProtectScope() {
  if (active_) t_current = outer_;
}

void ProtectScope::NoteError(std::string_view vuid, const Location& loc) {
  ProtectScope* scope = t_current;
  if (!scope || scope->withheld_) return;
  scope->withheld_ = true;  // first, so that it stands if the text below cannot be made
  scope->function_ = loc.Function();
  scope->vuid_.assign(vuid);
  std::string path = loc.Path();
  scope->where_.assign(loc.Function()).append("()");
  if (!path.empty()) scope->where_.append(": ").append(path);
}

}  // namespace asval
