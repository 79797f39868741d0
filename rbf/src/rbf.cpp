// The global RBF interpolant (vitri::Rbf): the object: construction, copies, accessors. The method and
// the state are described in rbf_impl.hpp; each operation has its own file (listed there).

#include "vitri/rbf/rbf.hpp"

#include "rbf_impl.hpp"

#include <memory>

namespace vitri {

Rbf::Rbf() : impl_(std::make_unique<Impl>()) {}
Rbf::Rbf(const Constraints& constraints, const RbfOptions& options) : Rbf() {
  fit(constraints, options);
}
Rbf::~Rbf() = default;
Rbf::Rbf(const Rbf& o) : impl_(std::make_unique<Impl>(*o.impl_)) {}
Rbf& Rbf::operator=(const Rbf& o) {
  if (this != &o) impl_ = std::make_unique<Impl>(*o.impl_);
  return *this;
}
Rbf::Rbf(Rbf&&) noexcept = default;
Rbf& Rbf::operator=(Rbf&&) noexcept = default;

bool Rbf::fitted() const {
  return impl_->fitted;
}
std::size_t Rbf::size() const {
  return impl_->cons.size();
}
const Constraints& Rbf::constraints() const {
  return impl_->cons;
}
std::vector<ConstraintId> Rbf::constraint_ids() const {
  return impl_->ids.ids();
}
ConstraintId Rbf::next_id() const {
  return impl_->ids.next();
}
bool Rbf::contains(ConstraintId id) const {
  return impl_->ids.contains(id);
}
Point3 Rbf::point(ConstraintId id) const {
  return impl_->cons.points[impl_->ids.row(id)];
}
double Rbf::value_of(ConstraintId id) const {
  return impl_->cons.values[impl_->ids.row(id)];
}
Box3 Rbf::bounding_box() const {
  Box3 b;
  for (const Point3& p : impl_->cons.points) b.extend(p);
  return b;
}
const RbfOptions& Rbf::options() const {
  return impl_->opt;
}
const FitReport& Rbf::report() const {
  return impl_->rep;
}
std::size_t Rbf::edits_since_fit() const {
  return impl_->edits;
}
std::size_t Rbf::refits_by_edits() const {
  return impl_->refits;
}

}  // namespace vitri
