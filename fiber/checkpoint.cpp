// The fiber system's part of a checkpoint (system.hpp, FiberSystem::save).
#include "checkpoint.hpp"

#include "system.hpp"

namespace fiber {

namespace {

// Per fiber: root pose at t^n and t^(n+1), root and tip loads, support moments, tension iterations.
constexpr std::size_t kFiberValues = 17;

void load_exact(const fsi::H5File& h5, const std::string& name, std::vector<double>& into) {
  std::vector<double> a = h5.read_doubles(name);
  if (a.size() != into.size())
    fsi::fail("checkpoint {}: {} has {} values, the fibers {} (other fibers?)", h5.path().string(), name,
              a.size(), into.size());
  into = std::move(a);
}

void put(std::vector<double>& a, const Vec2& v) { a.push_back(v.x()), a.push_back(v.y()); }
Vec2 get(const double*& p) {
  const Vec2 v(p[0], p[1]);
  p += 2;
  return v;
}

}  // namespace

void FiberSystem::save(fsi::H5File& h5) const {
  for (const auto& [name, v] :
       {std::pair{"x", &m_x}, {"x_old", &m_x_old}, {"x_new", &m_x_new}, {"x_star", &m_x_star},
        {"x_step_old", &m_x_step_old}, {"x_initial", &m_x_initial}, {"force", &m_force},
        {"repulsion", &m_repulsion}, {"tension", &m_tension}, {"coef", &m_coef}, {"ref", &m_ref}})
    h5.write(std::string("fiber/") + name, *v);
  std::vector<double> per;
  for (const Fiber& f : m_fibers) {
    put(per, f.root_pose_old.position), put(per, f.root_pose_old.direction);
    put(per, f.root_pose_new.position), put(per, f.root_pose_new.direction);
    put(per, f.root_load.force), per.push_back(f.root_load.moment);
    put(per, f.tip_load.force), per.push_back(f.tip_load.moment);
    per.push_back(f.root_moment), per.push_back(f.tip_moment), per.push_back(f.tension_iterations);
  }
  h5.write("fiber/per_fiber", per);
  std::vector<double> inertia;  // the root load's mass (xx, xy, yy) and acceleration
  for (const Fiber& f : m_fibers) {
    const auto& l = f.root_load;
    inertia.insert(inertia.end(), {l.mass(0, 0), l.mass(0, 1), l.mass(1, 1)});
    put(inertia, l.accel);
  }
  h5.write("fiber/root_inertia", inertia);
  std::vector<double> acc;
  for (const auto* loads : {&m_root_acc, &m_tip_acc})
    for (const EndLoad& l : *loads) put(acc, l.force), acc.push_back(l.moment);
  h5.write("fiber/accumulated_loads", acc);
  h5.write("fiber/clock", std::vector<double>{m_time, m_last_h, m_sub_time});
  h5.write("fiber/counts", std::vector<std::int64_t>{m_steps, m_substeps_done});
}

void FiberSystem::load(const fsi::H5File& h5) {
  for (const auto& [name, v] :
       {std::pair{"x", &m_x}, {"x_old", &m_x_old}, {"x_new", &m_x_new}, {"x_star", &m_x_star},
        {"x_step_old", &m_x_step_old}, {"x_initial", &m_x_initial}, {"force", &m_force},
        {"repulsion", &m_repulsion}, {"tension", &m_tension}, {"coef", &m_coef}, {"ref", &m_ref}})
    load_exact(h5, std::string("fiber/") + name, *v);
  const std::vector<double> per = h5.read_doubles("fiber/per_fiber");
  if (per.size() != kFiberValues * m_fibers.size())
    fsi::fail("checkpoint {}: it holds another number of fibers", h5.path().string());
  const double* p = per.data();
  for (Fiber& f : m_fibers) {
    f.root_pose_old.position = get(p), f.root_pose_old.direction = get(p);
    f.root_pose_new.position = get(p), f.root_pose_new.direction = get(p);
    f.root_load.force = get(p), f.root_load.moment = *p++;
    f.tip_load.force = get(p), f.tip_load.moment = *p++;
    f.root_moment = *p++, f.tip_moment = *p++, f.tension_iterations = static_cast<int>(*p++);
  }
  const std::vector<double> inertia = h5.read_doubles("fiber/root_inertia");
  if (inertia.size() != 5 * m_fibers.size())
    fsi::fail("checkpoint {}: its root inertia is of other fibers", h5.path().string());
  p = inertia.data();
  for (Fiber& f : m_fibers) {
    auto& l = f.root_load;
    l.mass << p[0], p[1], p[1], p[2];
    p += 3;
    l.accel = get(p);
  }
  const std::vector<double> acc = h5.read_doubles("fiber/accumulated_loads");
  if (acc.size() != 3 * (m_root_acc.size() + m_tip_acc.size()))
    fsi::fail("checkpoint {}: its end loads are of other fibers", h5.path().string());
  p = acc.data();
  for (auto* loads : {&m_root_acc, &m_tip_acc})
    for (EndLoad& l : *loads) l.force = get(p), l.moment = *p++;
  const auto clock = h5.read_doubles("fiber/clock");
  m_time = clock.at(0), m_last_h = clock.at(1), m_sub_time = clock.at(2);
  const auto counts = h5.read_int64s("fiber/counts");
  m_steps = counts.at(0), m_substeps_done = counts.at(1);
}

}  // namespace fiber
