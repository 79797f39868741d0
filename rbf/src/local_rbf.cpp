// vitri::LocalRbf: the partition-of-unity variational function (see local_rbf.hpp, docs/local_rbf.md): the
// object, the fit's options, the accessors and the validator. The state is in local_rbf_impl.hpp; each
// operation has its own file (listed there).
#include "vitri/rbf/local_rbf.hpp"

#include "local_rbf_impl.hpp"
#include "vitri/core/error.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <mutex>
#include <stdexcept>
#include <string>

namespace vitri {

using namespace local_detail;

LocalRbf::LocalRbf() : impl_(std::make_unique<Impl>()) {}
LocalRbf::LocalRbf(const Constraints& constraints, const LocalRbfOptions& options) : LocalRbf() {
  fit(constraints, options);
}
LocalRbf::~LocalRbf() = default;
LocalRbf::LocalRbf(LocalRbf&&) noexcept = default;
LocalRbf& LocalRbf::operator=(LocalRbf&&) noexcept = default;

const LocalFitReport& LocalRbf::fit(const Constraints& constraints, const LocalRbfOptions& options) {
  if (options.min_per_patch < 5 || options.min_per_patch > options.max_per_patch)
    throw InvalidArgument("local RBF: min_per_patch must be in [5, max_per_patch], got " +
                          std::to_string(options.min_per_patch));
  if (!(options.overlap > 1.0) || !std::isfinite(options.overlap))
    throw InvalidArgument("local RBF: overlap must be > 1, got " + std::to_string(options.overlap));
  if (!(options.domain_factor >= 1.0) || !std::isfinite(options.domain_factor))
    throw InvalidArgument("local RBF: domain_factor must be >= 1, got " + std::to_string(options.domain_factor));
  if (!(options.smoothing >= 0.0) || !std::isfinite(options.smoothing))
    throw InvalidArgument("local RBF: smoothing must be >= 0, got " + std::to_string(options.smoothing));
  if (!(options.duplicate_tolerance >= 0.0) || options.max_depth < 0 || options.max_depth > 40)
    throw InvalidArgument("local RBF: duplicate_tolerance must be >= 0 and max_depth in [0, 40]");
  impl_->opt = options;
  impl_->fit_all(constraints, options.domain);
  return impl_->report;
}

bool LocalRbf::fitted() const { return impl_->fitted; }
std::size_t LocalRbf::size() const { return impl_->live; }
const LocalRbfOptions& LocalRbf::options() const { return impl_->opt; }
const LocalFitReport& LocalRbf::report() const { return impl_->report; }
Box3 LocalRbf::domain() const { return impl_->tree.root_box(); }

const Constraints& LocalRbf::constraints() const {
  std::lock_guard<std::mutex> lock(impl_->cache_mutex);
  if (!impl_->cache_valid) {
    impl_->cache = Constraints{};
    impl_->cache.points.reserve(size());
    impl_->cache.values.reserve(size());
    for (std::size_t s = 0; s < impl_->slot_point.size(); ++s)
      if (impl_->slot_alive[s]) impl_->cache.add(impl_->slot_point[s], impl_->slot_value[s]);
    impl_->cache_valid = true;
  }
  return impl_->cache;
}

void LocalRbf::release_constraints_cache() const {
  std::lock_guard<std::mutex> lock(impl_->cache_mutex);
  impl_->cache = Constraints{};
  impl_->cache_valid = false;
}

Box3 LocalRbf::bounding_box() const {
  Box3 b;
  for (std::size_t s = 0; s < impl_->slot_point.size(); ++s)
    if (impl_->slot_alive[s]) b.extend(impl_->slot_point[s]);
  return b;
}

std::vector<ConstraintId> LocalRbf::constraint_ids() const {
  std::vector<ConstraintId> ids;
  ids.reserve(size());
  for (std::size_t s = 0; s < impl_->slot_alive.size(); ++s)
    if (impl_->slot_alive[s]) ids.push_back(s);
  return ids;
}

ConstraintId LocalRbf::next_id() const { return impl_->slot_point.size(); }

bool LocalRbf::contains(ConstraintId id) const { return id < impl_->slot_alive.size() && impl_->slot_alive[id]; }

Point3 LocalRbf::point(ConstraintId id) const { return impl_->slot_point[impl_->slot_of(id)]; }

double LocalRbf::value_of(ConstraintId id) const { return impl_->slot_value[impl_->slot_of(id)]; }

void LocalRbf::validate() const {
  const Impl& m = *impl_;
  m.tree.validate();
  for (std::uint32_t c = 0; c < m.tree.capacity(); ++c) {
    const Cell& cell = m.tree.cell(c);
    if (!cell.alive) continue;
    const std::size_t n = m.index.count_ball(cell.center, cell.radius * cell.radius, m.opt.max_per_patch);
    const bool want_children = n > m.opt.max_per_patch && cell.depth < m.opt.max_depth;
    if (want_children == cell.leaf())
      throw std::logic_error("local RBF: cell " + std::to_string(c) + " at " + format_point(cell.center) +
                             " breaks the split rule (" + std::to_string(n) + " constraints in its ball)");
    if (!cell.leaf()) continue;
    const PatchRecord* r = c < m.patches.size() ? &m.patches[c] : nullptr;
    if (!r || r->center != cell.center || r->radius2 != cell.radius * cell.radius || r->coef != cell.coef.data() ||
        r->terms != cell.terms)
      throw std::logic_error("local RBF: the patch record of leaf " + std::to_string(c) + " is stale");
  }
  if (m.index.size() != m.live ||
      static_cast<std::size_t>(std::count(m.slot_alive.begin(), m.slot_alive.end(), std::uint8_t{1})) != m.live)
    throw std::logic_error("local RBF: constraint counts disagree");
}

}  // namespace vitri
