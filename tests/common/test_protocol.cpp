// Protocol messages: pack/unpack round trips, and refusal of mismatched or damaged messages.
#include <catch2/catch.hpp>

#include "protocol.hpp"

using namespace fsi::proto;

template <class M>
M round_trip(const M& m, std::int64_t step = 7) {
  const auto bytes = pack_message(m, step);
  M back;
  if constexpr (std::is_same_v<M, Text>) back.tag = m.tag;
  std::int64_t s = -1;
  unpack_message(bytes, back, &s);
  CHECK(s == step);
  return back;
}

TEST_CASE("every message survives a round trip") {
  GridInfo g{3, 2, 1, 0, {0, 0.5, 1, 1.5}, {0, 0.1, 0.3}, 1000.0, 1};
  const auto g2 = round_trip(g);
  CHECK(g2.can_iterate == 1);
  CHECK(g2.nx == 3);
  CHECK(g2.periodic_x == 1);
  CHECK(g2.y_face == g.y_face);
  CHECK(g2.density == 1000.0);

  BodyMeshes bm;
  bm.bodies.push_back(
      {"bar", BodyKind::elastic, {0, 0, 1, 0, 0, 1}, {0, 1, 2}, {0, 1, 1, 2, 2, 0}, 0});
  bm.bodies.push_back({"cylinder", BodyKind::rigid_fixed, {}, {}, {}, 1});
  bm.bodies.push_back({"disk", BodyKind::elastic, {}, {}, {}, 1});  // a free rigid body
  bm.can_iterate = 1;
  const auto bm2 = round_trip(bm);
  CHECK(bm2.can_iterate == 1);
  REQUIRE(bm2.bodies.size() == 3);
  CHECK(bm2.bodies[0].name == "bar");
  CHECK(bm2.bodies[0].tri == bm.bodies[0].tri);
  CHECK(bm2.bodies[0].rigid == 0);
  CHECK(bm2.bodies[1].kind == BodyKind::rigid_fixed);
  CHECK(bm2.bodies[2].kind == BodyKind::elastic);
  CHECK(bm2.bodies[2].rigid == 1);

  FiberLayout fl;
  fl.fibers.push_back({"f0", 63, 0.002, 1, "wall", 12, 0.25, 0.5, 0.125, 0.1});
  const auto fl2 = round_trip(fl);
  CHECK(fl2.fibers[0].body == "wall");
  CHECK(fl2.fibers[0].edge_s == 0.25);
  CHECK(fl2.fibers[0].root_y == 0.125);
  CHECK(fl2.fibers[0].line_density == 0.1);

  Text t{Tag::final_report, "{\"a\": 1}"};
  CHECK(round_trip(t).text == t.text);

  StepBegin sb{41, 0.041, 1e-3, Action::stop, 3, 1};
  const auto sb2 = round_trip(sb);
  CHECK(sb2.step == 41);
  CHECK(sb2.iteration == 3);
  CHECK(sb2.may_repeat == 1);
  CHECK(sb2.action == Action::stop);

  FluidInput fi;
  // A rigid body beside an elastic one: the elastic part of alpha on every face of both.
  fi.solid_u = {{1, 5, 9}, {0.5, 1.0, 0.25}, {0.1, 0.2, 0.3}, {0.5, 0.0, 0.125}};
  fi.solid_v = {{2}, {0.75}, {-0.1}, {0.0}};
  fi.force_v = {{4}, {-2.5}};
  fi.sample_u = {3, 4};
  fi.sample_p = {7};
  const auto fi2 = round_trip(fi);
  CHECK(fi2.solid_u.index == fi.solid_u.index);
  CHECK(fi2.solid_u.velocity == fi.solid_u.velocity);
  CHECK(fi2.solid_u.elastic == fi.solid_u.elastic);
  CHECK(fi2.solid_v.index == fi.solid_v.index);
  CHECK(fi2.solid_v.elastic == fi.solid_v.elastic);
  fi.solid_u.elastic.clear(), fi.solid_v.elastic.clear();  // every body elastic: none sent
  const auto fi3 = round_trip(fi);
  CHECK(fi3.solid_u.elastic.empty());
  CHECK(fi3.solid_v.elastic.empty());
  CHECK(fi3.solid_u.body.empty());
  // The faces' bodies (version 9): on every face of both families.
  fi.solid_u.body = {0, -1, 1};
  fi.solid_v.body = {1};
  const auto fi4 = round_trip(fi);
  CHECK(fi4.solid_u.body == fi.solid_u.body);
  CHECK(fi4.solid_v.body == fi.solid_v.body);
  fi.solid_v.body.clear();
  FluidInput back;
  CHECK_THROWS_WITH(unpack_message(pack_message(fi, 1), back),
                    Catch::Contains("faces' bodies sent for some faces only"));
  fi.solid_u.body.clear();
  CHECK(fi2.force_v.force == fi.force_v.force);
  CHECK(fi2.sample_u == fi.sample_u);
  CHECK(fi2.sample_p == fi.sample_p);

  FluidOutput fo{{1.5, -2}, {}, {0.25}, {}, {4.5}, 0.3, 1e-15, 2.5};
  const auto fo2 = round_trip(fo);
  CHECK(fo2.fs_u == fo.fs_u);
  CHECK(fo2.cfl == 0.3);
  CHECK(fo2.p_sample == fo.p_sample);

  SolidInput si{{{1, 2, 3, 4}, {}}, {{0.5, -0.5, 0, 1}, {}}, {{}, {0.1, 0, 0.2, 0, 0, 0}}};
  const auto si2 = round_trip(si);
  CHECK(si2.force == si.force);
  CHECK(si2.velocity == si.velocity);
  CHECK(si2.root_mass == si.root_mass);
  SolidState ss{0.5, {{0, 0, 1, 0}}, {{0, 1, 0, 1}}};
  const auto ss2 = round_trip(ss);
  CHECK(ss2.x == ss.x);
  CHECK(ss2.v == ss.v);
  FiberInput fin{{{0.1, 0.2}}, {{0, 0, 0, 1}}};
  CHECK(round_trip(fin).root_pose == fin.root_pose);
  FiberState fs{1.0, {{0, 0, 0, 1}}, {{0, 0, 0, 0.9}}, {1, 2, 3}, {0.5, 0, 0.01}, {-1, 2}};
  const auto fs2 = round_trip(fs);
  CHECK(fs2.x_old == fs.x_old);
  CHECK(fs2.root_load == fs.root_load);
  CHECK(fs2.root_mass == fs.root_mass);
  CHECK(fs2.root_accel == fs.root_accel);
}

TEST_CASE("damaged or mismatched messages are refused") {
  StepBegin sb{1, 0.1, 0.1, Action::step};
  auto bytes = pack_message(sb, 1);
  SECTION("another message type") {
    FluidInput fi;
    CHECK_THROWS_WITH(unpack_message(bytes, fi),
                      Catch::Contains("expected message 'fluid_input', got 'step_begin'"));
  }
  SECTION("an elastic fraction for some faces only") {
    FluidInput fi;
    fi.solid_u = {{1, 5}, {0.5, 1.0}, {0.1, 0.2}, {0.5}};
    FluidInput back;
    CHECK_THROWS_WITH(unpack_message(pack_message(fi, 1), back),
                      Catch::Contains("face solid arrays of different lengths"));
    fi.solid_u.elastic = {0.5, 0.0};
    fi.solid_v = {{3}, {0.25}, {0.0}, {}};  // the v faces without theirs
    CHECK_THROWS_WITH(unpack_message(pack_message(fi, 1), back),
                      Catch::Contains("elastic part of alpha sent for some faces only"));
  }
  SECTION("a body neither rigid nor not") {
    BodyMeshes bm;
    bm.bodies.push_back({"disk", BodyKind::elastic, {}, {}, {}, 2});
    BodyMeshes back;
    CHECK_THROWS_WITH(unpack_message(pack_message(bm, 0), back),
                      Catch::Contains("body 'disk' has rigid = 2, not 0 or 1"));
  }
  SECTION("another protocol version") {
    Header h;
    std::memcpy(&h, bytes.data(), sizeof h);
    h.version = kVersion + 1;
    std::memcpy(bytes.data(), &h, sizeof h);
    StepBegin back;
    CHECK_THROWS_WITH(unpack_message(bytes, back), Catch::Contains("message of version"));
  }
  SECTION("truncated") {
    bytes.resize(bytes.size() - 3);
    StepBegin back;
    CHECK_THROWS_WITH(unpack_message(bytes, back), Catch::Contains("truncated"));
  }
  SECTION("trailing bytes") {
    bytes.push_back(std::byte{0});
    StepBegin back;
    CHECK_THROWS_WITH(unpack_message(bytes, back), Catch::Contains("trailing bytes"));
  }
  SECTION("a vector length that does not fit") {
    FluidInput fi;
    fi.sample_u = {1, 2, 3};
    auto b = pack_message(fi, 0);
    // sample_u's length sits before its 3 ints and sample_v's and sample_p's (empty) lengths.
    const std::int64_t huge = 1000;
    std::memcpy(b.data() + b.size() - 8 - 8 - 12 - 8, &huge, sizeof huge);
    FluidInput back;
    CHECK_THROWS_WITH(unpack_message(b, back), Catch::Contains("does not fit"));
  }
}

// A link packs every message into one kept buffer: a short message after a long one must carry
// its own length only, and the buffer grows once, not per message.
TEST_CASE("messages packed one after another into a kept buffer") {
  std::vector<std::byte> buffer;
  FluidInput big;
  big.sample_u.assign(5000, 3);
  big.force_u.index.assign(2000, 4), big.force_u.force.assign(2000, -1.5);
  const std::size_t n_big = pack_message(big, 3, buffer);
  CHECK(buffer.size() >= n_big);
  const auto* data = buffer.data();
  StepBegin sb{4, 0.4, 0.1, Action::stop};
  const std::size_t n_small = pack_message(sb, 4, buffer);
  CHECK(n_small < n_big);
  CHECK(buffer.data() == data);  // no reallocation for the shorter message
  StepBegin back;
  std::int64_t step = -1;
  unpack_message(buffer.data(), n_small, back, &step);
  CHECK(step == 4);
  CHECK(back.action == Action::stop);
  CHECK(back.time == 0.4);
  // The long message again, over the short one's bytes: equal to a freshly packed copy.
  const std::size_t n_again = pack_message(big, 3, buffer);
  const auto fresh = pack_message(big, 3);
  REQUIRE(n_again == fresh.size());
  CHECK(std::memcmp(buffer.data(), fresh.data(), n_again) == 0);
  FluidInput big2;
  unpack_message(buffer.data(), n_again, big2);
  CHECK(big2.sample_u == big.sample_u);
  CHECK(big2.force_u.force == big.force_u.force);
}
