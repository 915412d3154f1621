// The solid's part of a checkpoint: the Newmark state of every body (u, v, M a, positions), the
// contact slots with their active set and multipliers, the clock, the run's counters, and the
// matrix values of the factor a step keeps (so a resumed run continues bit for bit).
#include "checkpoint.hpp"

#include "program.hpp"

namespace solid {

namespace {

// One contact slot as numbers: the pair, the last detection (gap, feature, normal) and the
// active-set state.
constexpr std::size_t kSlotValues = 12;

std::vector<double> slots_to_numbers(const std::vector<ContactSlot>& slots) {
  std::vector<double> a;
  for (const ContactSlot& c : slots)
    a.insert(a.end(), {double(c.slave_body), double(c.slave_node), double(c.master_body),
                       double(c.plane), c.gap, double(c.m0), double(c.m1), c.xi, c.normal[0],
                       c.normal[1], c.active ? 1.0 : 0.0, c.lambda});
  return a;
}

std::vector<ContactSlot> numbers_to_slots(const std::vector<double>& a, const fsi::H5File& h5) {
  if (a.size() % kSlotValues != 0) fsi::fail("checkpoint {}: the contact slots are damaged", h5.path().string());
  std::vector<ContactSlot> slots(a.size() / kSlotValues);
  for (std::size_t k = 0; k < slots.size(); ++k) {
    const double* v = &a[kSlotValues * k];
    ContactSlot& c = slots[k];
    c.slave_body = int(v[0]), c.slave_node = int(v[1]), c.master_body = int(v[2]), c.plane = int(v[3]);
    c.gap = v[4], c.m0 = int(v[5]), c.m1 = int(v[6]), c.xi = v[7], c.normal = Vec2{v[8], v[9]};
    c.active = v[10] != 0, c.lambda = v[11];
  }
  return slots;
}

}  // namespace

void SolidProgram::save(fsi::H5File& h5) const {
  StepState s;
  m_solver->save_state(s);
  fsi::write_vectors(h5, "solid/u", s.u);
  fsi::write_vectors(h5, "solid/v", s.v);
  fsi::write_vectors(h5, "solid/ma", s.ma);
  fsi::write_vectors(h5, "solid/x", s.x);
  fsi::write_vectors(h5, "solid/contact", s.contact);
  fsi::write_vectors(h5, "solid/root_mass_tangent", s.root_mass_tangent);
  h5.write("solid/slots", slots_to_numbers(s.slots));
  // Whether each slot's feature is a zone vertex (its zone's radius doubles for the next
  // detection: contact.cpp). A dataset of its own: files without it (written before it
  // existed) read as no zone, so their first step after a resume may differ from the run's.
  std::vector<double> zone;
  for (const ContactSlot& c : s.slots) zone.push_back(c.zone ? 1.0 : 0.0);
  h5.write("solid/slot_zone", zone);
  h5.write("solid/clock", std::vector<double>{s.time, s.contact_force_factor});
  h5.write("solid/counts", std::vector<std::int64_t>{s.step, m_steps, m_repeats, m_newton_total,
                                                     m_newton_max, m_cut_steps});
  h5.write("solid/t_end", std::vector<double>{m_rt.settings().t_end});
  h5.write("solid/contact_entries", m_solver->contact_entries());
  // The energy balance's works and the coupling forces of the last step (its f^n).
  h5.write("solid/work", std::vector<double>{m_coupling_work, m_contact_work});
  fsi::write_vectors(h5, "solid/external_used", m_external_used);
  const KeptFactor k = m_solver->kept_factor();
  h5.write("solid/kept_factor", k.values);
  h5.write("solid/kept_factor_info", std::vector<double>{k.c0, k.matrix_floor});
}

void SolidProgram::load(const fsi::H5File& h5) {
  // A static analysis walks the load factor t / t_end: another t_end would be another problem.
  const double t_end = h5.read_doubles("solid/t_end").at(0);
  if (m_cfg.model.settings.analysis == Analysis::statics && t_end != m_rt.settings().t_end)
    throw fsi::InputError(fmt::format(
        "time.t_end = {:g} differs from the {:g} of the static analysis being resumed (its load "
        "factor is t / t_end); keep t_end (in {})",
        m_rt.settings().t_end, t_end, m_rt.scene().file().string()));
  StepState s;
  s.u = fsi::read_vectors(h5, "solid/u");
  s.v = fsi::read_vectors(h5, "solid/v");
  s.ma = fsi::read_vectors(h5, "solid/ma");
  s.x = fsi::read_vectors(h5, "solid/x");
  s.contact = fsi::read_vectors(h5, "solid/contact");
  s.root_mass_tangent = fsi::read_vectors(h5, "solid/root_mass_tangent");
  s.slots = numbers_to_slots(h5.read_doubles("solid/slots"), h5);
  if (h5.exists("solid/slot_zone")) {
    const std::vector<double> zone = h5.read_doubles("solid/slot_zone");
    if (zone.size() != s.slots.size())
      fsi::fail("checkpoint {}: {} slot zone flags for {} contact slots", h5.path().string(),
                zone.size(), s.slots.size());
    for (std::size_t k = 0; k < zone.size(); ++k) s.slots[k].zone = zone[k] != 0;
  }
  const auto clock = h5.read_doubles("solid/clock");
  s.time = clock.at(0), s.contact_force_factor = clock.at(1);
  const auto counts = h5.read_int64s("solid/counts");
  s.step = counts.at(0), m_steps = counts.at(1), m_repeats = counts.at(2);
  m_newton_total = counts.at(3), m_newton_max = counts.at(4);
  m_cut_steps = counts.size() > 5 ? counts[5] : 0;  // (checkpoints before step_cutbacks: none)
  m_solver->restore_state(s);
  // (Checkpoints written before the energy balance: the works count from the resumed time, and
  // the first step takes its f^n as zero.)
  m_coupling_work = m_contact_work = 0;
  m_external_used.clear();
  if (h5.exists("solid/work")) {
    const auto w = h5.read_doubles("solid/work");
    m_coupling_work = w.at(0), m_contact_work = w.at(1);
    m_external_used = fsi::read_vectors(h5, "solid/external_used");
  }
  if (h5.exists("solid/contact_entries"))
    m_solver->restore_contact_entries(h5.read_int64s("solid/contact_entries"));
  KeptFactor k;
  if (h5.exists("solid/kept_factor") && h5.exists("solid/kept_factor_info")) {
    k.values = h5.read_doubles("solid/kept_factor");
    const auto info = h5.read_doubles("solid/kept_factor_info");
    k.c0 = info.at(0), k.matrix_floor = info.at(1);
  }
  m_solver->restore_kept_factor(k);
}

}  // namespace solid
