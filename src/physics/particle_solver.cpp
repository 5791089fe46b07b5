// ParticleSolver's host side. Over ~600 lines: the state (grouped by concern in solver_state),
// the views the kernels read, the substep and spawning (add_batch, emitters, the spawn schedule)
// are still one file; spawning is the part to move out next.
#include "physics/particle_solver.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <exception>
#include <optional>
#include <utility>

#include "core/buffer.hpp"
#include "core/error.hpp"
#include "core/exec.hpp"
#include "core/log.hpp"
#include "core/step_graph.hpp"
#include "kernels/physics/solver.hpp"

namespace seamless {

namespace K = kernels;

namespace {

// A spawn further than this outside the scanned scene's bounding box is reported: objects are
// spawned above the scene, within a metre or so of what the camera saw.
constexpr float kScanMargin = 1.f;

template <class T> void grow(Buffer<T>& b, std::int64_t cap, std::int64_t keep, Device d) {
  if (b.size() >= cap) return;
  Buffer<T> nb(cap, d);
  if (keep > 0) memory::copy(nb.data(), d, b.data(), d, sizeof(T) * static_cast<std::size_t>(keep));
  b = std::move(nb);
}

template <class T> void upload_at(Buffer<T>& b, std::int64_t offset, const std::vector<T>& v) {
  if (v.empty()) return;
  memory::copy(b.data() + offset, b.device(), v.data(), Device::CPU, sizeof(T) * v.size());
}

}  // namespace

// The solver's state by concern; ParticleSolver::Impl derives from them, so the code names each
// member directly. Buffers on the solver's device; "slot order" is the state between steps in the
// last substep's sorted order (kernels/physics/sim_views.hpp).
namespace solver_state {

// Per-particle state: slot order (slot_id holds the particle id of each slot), the per-particle
// constants and the id-order copies, and the sorted scratch of a substep.
struct ParticleState {
  Buffer<vec3> x, v, pred;
  Buffer<float> w;
  Buffer<std::uint32_t> phase;
  Buffer<int> slot_id;
  // id order: per-particle constants; positions and phases copied out for device_positions()
  Buffer<vec3> rest, x_id;
  Buffer<std::uint32_t> phase_id;
  Buffer<vec4> rsdf, sdf_at;
  Buffer<K::Packed> spk, spl, spd, svh, cnv;  // packed copies for the neighbour loops (sim_views.hpp)
  Buffer<K::Packed> pair_w;                   // CPU: kernel values per list entry (SimViews::pair_w)
  // sort and sorted scratch
  Buffer<std::uint32_t> key, sphase;
  Buffer<int> order, rank, ncontacts;
  Buffer<vec3> sx, sp, sp0, sv, tmp, vtmp, scene_n;
  Buffer<float> sw;
  Buffer<int> counters;  // overflow, longest lists, largest speed (kernels/physics/sim_views.hpp)
};

// The neighbour grid of the dynamic particles and their lists (kernels/physics/grid.hpp).
struct GridState {
  Buffer<int> nnbr, nsnbr, nsolid, nbr, snbr;
  Buffer<int> cell_start;
  int bits = 4;
};

// The fluid's per-particle quantities and its constants (kernels/physics/fluid.hpp).
struct FluidState {
  Buffer<vec3> vort, cnormal;
  Buffer<float> lambda, density, h_rho, vort_len;
  float rho0 = 1.f, eps = 0.f;
};

// The static scene the contacts meet: scene particles in their own grid, the scene SDF.
// static_points: the first n_static hold the scene's particles (add_static_particles);
// collider_points: the first n_colliders this frame's kinematic colliders (set_collider_particles),
// kept after the scene's points in the same static grid. Both on the solver's device, so that
// points handed over on the device never pass through the host.
struct StaticScene {
  Buffer<vec3> static_points, collider_points;
  std::int64_t n_static = 0, n_colliders = 0;
  std::int64_t static_count() const { return n_static + n_colliders; }
  // The scene particles' bounds (report_placement), found when first asked after a change.
  vec3 static_lo{}, static_hi{};
  bool static_bounds_known = false;
  Buffer<vec3> stat;
  Buffer<int> scell_start;
  Buffer<vec3> static_raw;  // rebuild_static's scratch: the points before sorting, their keys and order
  Buffer<std::uint32_t> static_keys;
  Buffer<int> static_idx;
  K::GridSpec sgrid{};
  K::SceneSdf sdf{};
  Buffer<float> sdf_grid;
};

// Rigid bodies (shape matching, kernels/physics/solids.hpp): host copies and device buffers.
struct RigidState {
  std::vector<int> body_start, body_count, body_chunk_start, body_chunk_count, chunk_start, chunk_count, chunk_body;
  std::vector<float> body_stiffness;
  Buffer<int> d_body_start, d_body_count, d_body_chunk_start, d_body_chunk_count, d_chunk_start, d_chunk_count,
      d_chunk_body;
  Buffer<float> d_body_stiffness;
  Buffer<int> body_contacts;
  Buffer<vec3> body_c, body_shift;
  Buffer<vec4> body_q;
  Buffer<mat3> body_R;
  Buffer<K::RigidSum> chunk_sum;
  Buffer<K::SlipSum> chunk_slip;
};

// Cloth constraints (global ids; kernels/physics/solids.hpp).
struct ClothState {
  std::vector<int> edge_a, edge_b;
  std::vector<float> edge_len, edge_k0, edge_limit0;
  std::vector<K::Quad> bends;
  std::vector<float> bend_rest, bend_k0;
  std::vector<int3> tris;                // every sheet's, for the self-collision lists
  std::vector<std::int64_t> colour_off;  // stretch edges of colour c: [colour_off[c], colour_off[c + 1])
  bool strain_limited = false;
  Buffer<int> d_edge_a, d_edge_b, bend_off, bend_list, tri_off, tri_list;
  Buffer<float> d_edge_len, d_edge_k, d_edge_limit, d_bend_rest, d_bend_k;
  Buffer<K::Quad> d_bends;
  Buffer<vec3> bend_delta;
  Buffer<int3> d_tris;
  int cloth_groups = 0;
};

// An emitter of the spawn list and how far it has got (run_emitters).
struct Emitter {
  SpawnParams s;
  double start = 0.0, distance = 0.0, budget = 0.0;
};

}  // namespace solver_state

struct ParticleSolver::Impl : solver_state::ParticleState,
                              solver_state::GridState,
                              solver_state::FluidState,
                              solver_state::StaticScene,
                              solver_state::RigidState,
                              solver_state::ClothState {
  SolverParams P;
  Device dev;
  std::int64_t n = 0, cap = 0;
  std::uint64_t state_version = 0, id_copy_version = ~std::uint64_t{0};  // x_id, phase_id of this version
  // bookkeeping
  std::int64_t n_fluid = 0, n_cloth = 0, n_rigid = 0, emitter_dropped = 0;
  SpawnSchedule schedule;
  SpawnSchedule::Gate gate;
  SceneObjects objects;  // what add_batch created, as the app and the renderer see it
  std::vector<solver_state::Emitter> emitters;
  double time = 0.0;
  std::int64_t steps = 0;
  // Anything a captured step points to or depends on (particle count, buffers, constraints, scene)
  // bumps the generation; a CUDA graph is captured for a generation that one step has already
  // run with, and replayed while the generation, dt and the substeps stay the same.
  std::uint64_t generation = 0, stepped_generation = ~std::uint64_t{0};
  StepGraph graph;  // the solver's stream, sort storage and CUDA graph (core/step_graph.hpp)

  Impl(const SolverParams& p, Device d) : P(p), dev(d), graph(d, "particle solver") {
    counters = Buffer<int>(5, d);
    counters.zero();
    compute_fluid_constants();
  }

  // rho_0 and the CFM epsilon from the rest lattice (cubic, one diameter spacing), so that a
  // fluid block spawned on that lattice starts with C_i = 0 in its interior.
  void compute_fluid_constants() {
    const float d = P.particle_diameter, h = P.fluid_smoothing * d;
    int k = static_cast<int>(std::ceil(P.fluid_smoothing)) + 1;
    double rho = 0.0;
    for (int z = -k; z <= k; ++z)
      for (int y = -k; y <= k; ++y)
        for (int x = -k; x <= k; ++x) rho += K::poly6(float(x * x + y * y + z * z) * d * d, h);
    rho0 = static_cast<float>(rho);
    double den = 0.0;
    for (int z = -k; z <= k; ++z)
      for (int y = -k; y <= k; ++y)
        for (int x = -k; x <= k; ++x) den += length2(K::spiky_grad(vec3{float(x), float(y), float(z)} * d, h) / rho0);
    eps = static_cast<float>(P.fluid_relaxation * den);
  }

  void ensure_capacity(std::int64_t need) {
    if (need > P.max_particles)
      throw Error("particle solver: " + std::to_string(need) + " particles needed, over solver.max_particles = " +
                  std::to_string(P.max_particles) + "; raise solver.max_particles");
    if (need <= cap) return;
    std::int64_t nc = std::min<std::int64_t>(P.max_particles, std::max<std::int64_t>({need, 2 * cap, 1024}));
    grow(x, nc, n, dev), grow(v, nc, n, dev), grow(w, nc, n, dev), grow(phase, nc, n, dev), grow(slot_id, nc, n, dev);
    grow(rest, nc, n, dev), grow(rsdf, nc, n, dev);
    for (auto* b : {&pred, &sx, &sp, &sp0, &sv, &tmp, &vtmp, &vort, &cnormal, &scene_n}) b->reserve_discard(nc, dev);
    for (auto* b : {&order, &rank, &ncontacts, &nnbr, &nsnbr, &nsolid}) b->reserve_discard(nc, dev);
    for (auto* b : {&sw, &lambda, &density, &h_rho, &vort_len}) b->reserve_discard(nc, dev);
    key.reserve_discard(nc, dev), sphase.reserve_discard(nc, dev), sdf_at.reserve_discard(nc, dev);
    for (auto* b : {&spk, &spl, &spd, &svh, &cnv}) b->reserve_discard(nc, dev);
    nbr.reserve_discard(nc * (P.max_neighbours + 1), dev);  // + 1: the spare slot (sim_views.hpp)
    if (dev == Device::CPU) pair_w.reserve_discard(nc * (P.max_neighbours + 1), dev);  // kernels::kCachePairs
    cap = nc;
  }

  // x_id and phase_id: the slot state's positions and phases in id order, copied when the state
  // changed since the last copy (on CUDA on the default stream, after the last step).
  void copy_to_id_order() {
    if (id_copy_version == state_version) return;
    x_id.reserve_discard(cap, dev), phase_id.reserve_discard(cap, dev);
    K::SimViews S = views(P.dt);
    with_exec(dev, [&]<class E>(const E& ex) { K::Integration<E>::slots_to_ids(ex, S, x_id.data(), phase_id.data()); });
    id_copy_version = state_version;
  }

  K::SimViews views(float dt) {
    K::SimViews S;
    K::SimConstants& c = S.c;
    const float d = P.particle_diameter;
    c.dt = dt, c.inv_dt = 1.f / dt, c.gravity = P.gravity;
    c.radius = 0.5f * d, c.diameter = d;
    c.h = P.fluid_smoothing * d;
    c.W = K::SphKernel::make(c.h);
    c.search_radius = std::max(c.h, 1.5f * d);
    c.max_speed = P.max_speed, c.omega = P.relaxation;
    c.static_friction = P.static_friction, c.kinetic_friction = P.kinetic_friction, c.restitution = P.restitution;
    c.fluid_friction = P.fluid_friction;
    c.rest_density = rho0, c.relaxation = eps;
    c.scorr_k = P.tensile_k;
    float wdq = K::poly6(P.tensile_dq * P.tensile_dq * c.h * c.h, c.h);
    c.scorr_inv_wdq = wdq > 0.f ? 1.f / wdq : 0.f;
    c.unilateral = P.fluid_unilateral ? 1 : 0, c.solid_density_scale = P.solid_density_scale;
    c.viscosity = P.viscosity, c.vorticity = P.vorticity, c.cohesion = P.cohesion,
    c.surface_tension = P.surface_tension;
    c.drag = P.drag, c.lift = P.lift, c.air_density = P.air_density, c.wind = P.wind;
    c.sleep_threshold = P.sleep_threshold;
    c.cloth_self_exclusion = 1.5f * d;
    c.strain_omega = P.cloth_strain_omega, c.strain_contact_weight = P.cloth_strain_contact_weight;
    c.max_neighbors = P.max_neighbours, c.max_static_neighbors = P.max_static_neighbours;
    c.rotation_iterations = P.rotation_iterations;
    S.n = n;
    S.x = x.data(), S.v = v.data(), S.w = w.data(), S.phase = phase.data(), S.slot_id = slot_id.data(),
    S.rest = rest.data();
    S.rsdf = rsdf.data(), S.pred = pred.data();
    S.key = key.data(), S.order = order.data(), S.rank = rank.data();
    S.sx = sx.data(), S.sp = sp.data(), S.sp0 = sp0.data(), S.sv = sv.data(), S.tmp = tmp.data(), S.vtmp = vtmp.data();
    S.sw = sw.data(), S.sphase = sphase.data(), S.lambda = lambda.data(), S.density = density.data(),
    S.h_rho = h_rho.data(), S.vort_len = vort_len.data();
    S.ncontacts = ncontacts.data(), S.vort = vort.data(), S.cnormal = cnormal.data(), S.sdf_at = sdf_at.data(),
    S.scene_n = scene_n.data();
    S.spk = spk.data(), S.spl = spl.data(), S.spd = spd.data(), S.svh = svh.data(), S.cnv = cnv.data(),
    S.pair_w = pair_w.data();
    S.grid = K::GridSpec::for_radius(c.search_radius, bits);
    S.cell_start = cell_start.data();
    S.nbr = nbr.data(), S.nnbr = nnbr.data(), S.snbr = snbr.data(), S.nsnbr = nsnbr.data(), S.nsolid = nsolid.data();
    // List layout (kernels/physics/sim_views.hpp): a particle's list contiguous where one thread
    // (CPU) or a group of lanes (a GPU with few particles, kernels::kPairLanes) walks it, entry k
    // of consecutive particles contiguous where one GPU thread per particle does.
    const int lanes = with_exec(dev, [&](const auto& ex) { return ex.lanes(n, K::kPairLanes); });
    if (dev == Device::CUDA && lanes < K::kRowMajorLanes) S.nbr_row = 1, S.nbr_col = n, S.snbr_row = 1, S.snbr_col = n;
    else S.nbr_row = P.max_neighbours + 1, S.nbr_col = 1, S.snbr_row = P.max_static_neighbours + 1, S.snbr_col = 1;
    S.counters = counters.data();
    S.ns = static_count();
    S.stat = stat.data(), S.sgrid = sgrid, S.scell_start = scell_start.data();
    S.sdf = sdf;
    S.nbodies = static_cast<int>(body_start.size());
    S.body_start = d_body_start.data(), S.body_count = d_body_count.data();
    S.body_chunk_start = d_body_chunk_start.data(), S.body_chunk_count = d_body_chunk_count.data();
    S.body_stiffness = d_body_stiffness.data(), S.body_contacts = body_contacts.data();
    S.body_c = body_c.data(), S.body_shift = body_shift.data(), S.body_q = body_q.data(), S.body_R = body_R.data();
    S.nchunks = static_cast<int>(chunk_start.size());
    S.chunk_start = d_chunk_start.data(), S.chunk_count = d_chunk_count.data(), S.chunk_body = d_chunk_body.data();
    S.chunk_sum = chunk_sum.data(), S.chunk_slip = chunk_slip.data();
    S.edge_a = d_edge_a.data(), S.edge_b = d_edge_b.data(), S.edge_len = d_edge_len.data();
    S.edge_k = d_edge_k.data(), S.edge_limit = d_edge_limit.data();
    S.bend_off = bend_off.data(), S.bend_list = bend_list.data(), S.bend_ids = d_bends.data();
    S.bend_rest = d_bend_rest.data(), S.bend_k = d_bend_k.data();
    S.nbends = static_cast<std::int64_t>(bends.size()), S.bend_delta = bend_delta.data();
    S.tri_off = tri_off.data(), S.tri_list = tri_list.data(), S.tri_ids = d_tris.data();
    S.has_cloth_constraints = n_cloth > 0 ? 1 : 0;
    return S;
  }

  // Grid size and the buffers it needs for n particles; a reallocation bumps the generation.
  void prepare_grid() {
    bits = K::GridSpec::bits_for(n);
    std::int64_t cells = std::int64_t{1} << (3 * bits);
    const void* before[2] = {cell_start.data(), snbr.data()};
    cell_start.reserve_discard(cells + 1, dev);
    if (static_count() > 0) snbr.reserve_discard(cap * (P.max_static_neighbours + 1), dev);
    const bool temp_moved = graph.reserve_temp(
        n, [&]<class E>(const E& ex) { return K::NeighbourGrid<E>::sort_cells_temp_bytes(ex, n, 3 * bits); });
    if (temp_moved) ++generation;
    if (before[0] != cell_start.data() || before[1] != snbr.data()) ++generation;
  }

  // Calls fn(executor): on CUDA, one that launches on the solver's own stream and sorts in its
  // own temp storage (so that a step can be captured as a graph).
  template <class F> void run(F&& fn) { graph.run(std::forward<F>(fn)); }

  // k substeps of dt / k. On CUDA they run on the solver's stream, ordered after what the default
  // stream holds and before what it gets next (no host synchronisation), as one graph launch
  // when solver.cuda_graph is set and the scene did not change since the last step (a graph is
  // recorded for a generation that one step has already run with: StepGraph::step).
  void advance(float dt, int k) {
    if (n == 0) return;
    ++state_version;
    prepare_grid();
    graph.step(P.cuda_graph && generation == stepped_generation, StepGraph::Key{generation, dt, k}, [&] {
      for (int i = 0; i < k; ++i) substep(dt / static_cast<float>(k));
    });
    stepped_generation = generation;
  }

  // Sort, grid and neighbour lists of the predicted positions (S.pred must be filled).
  template <class Ex> void build_neighbours(const Ex& ex, const K::SimViews& S) {
    using Grid = K::NeighbourGrid<Ex>;
    Grid::sort_cells(ex, S.key, S.order, n, 3 * bits);
    Grid::reorder(ex, S);
    Grid::cell_starts(ex, S.key, n, S.cell_start, std::int64_t{1} << (3 * bits));
    Grid::find_neighbors(ex, S);
  }

  // One substep of Algorithm 1 (dissertation section 4.2.2) with Macklin 2014's additions.
  void substep(float dt) {
    K::SimViews S = views(dt);
    const bool has_fluid = n_fluid > 0, has_cloth = !edge_a.empty() || !bends.empty();
    const bool effects = has_fluid || (n_cloth > 0 && (P.drag > 0.f || P.lift > 0.f));
    run([&]<class E>(const E& ex) {
      using Fluid = K::Fluid<E>;
      using Integration = K::Integration<E>;
      K::NeighbourGrid<E>::predict(ex, S);
      build_neighbours(ex, S);
      for (int i = 0; i < P.stabilization_iterations; ++i) K::Contacts<E>::stabilize(ex, S);
      for (int it = 0; it < P.iterations; ++it) {
        Fluid::prepare_constraints(ex, S);
        Fluid::solve_contacts_fluid(ex, S);
        std::swap(S.sp, S.tmp);
        K::Solids<E>::shape_match(ex, S);
        if (has_cloth) solve_cloth(ex, S);
      }
      if (strain_limited) limit_strain(ex, S);
      Integration::update_velocity(ex, S);
      if (effects) {
        Fluid::velocity_effects(ex, S, has_fluid);
        std::swap(S.sv, S.vtmp);
      }
      Integration::write_back(ex, S);
    });
  }

  template <class Ex> void solve_cloth(const Ex& ex, K::SimViews& S) {
    if (colour_off.size() > 1) K::Solids<Ex>::cloth_stretch(ex, S, colour_off.data(), colours());
    if (!bends.empty()) {
      K::Solids<Ex>::cloth_bend(ex, S);
      std::swap(S.sp, S.tmp);
    }
  }

  int colours() const { return static_cast<int>(colour_off.size()) - 1; }

  // Strain limiting after the iterations (Provot 1995): Gauss-Seidel over the edge colours.
  template <class Ex> void limit_strain(const Ex& ex, const K::SimViews& S) {
    if (colour_off.size() > 1)
      K::Solids<Ex>::cloth_strain_limit(ex, S, colour_off.data(), colours(), P.cloth_strain_passes);
  }

  void upload_bodies(const std::vector<vec3>& c, const std::vector<vec4>& q) {
    auto up = [&](Buffer<int>& b, const std::vector<int>& h) { b = Buffer<int>::from_host(h, dev); };
    up(d_body_start, body_start), up(d_body_count, body_count), up(d_body_chunk_start, body_chunk_start);
    up(d_body_chunk_count, body_chunk_count), up(d_chunk_start, chunk_start), up(d_chunk_count, chunk_count);
    up(d_chunk_body, chunk_body);
    d_body_stiffness = Buffer<float>::from_host(body_stiffness, dev);
    body_contacts = Buffer<int>(static_cast<std::int64_t>(body_stiffness.size()), dev);
    body_c = Buffer<vec3>::from_host(c, dev);
    body_shift = Buffer<vec3>(static_cast<std::int64_t>(c.size()), dev);
    body_q = Buffer<vec4>::from_host(q, dev);
    std::vector<mat3> R;
    for (vec4 r : q) R.push_back(quat_to_mat(r));
    body_R = Buffer<mat3>::from_host(R, dev);
    chunk_sum = Buffer<K::RigidSum>(static_cast<std::int64_t>(chunk_start.size()), dev);
    chunk_slip = Buffer<K::SlipSum>(static_cast<std::int64_t>(chunk_start.size()), dev);
  }

  void add_body(const ParticleBatch& b, std::int64_t first) {
    std::vector<vec3> c = body_c.to_host();
    std::vector<vec4> q = body_q.to_host();
    constexpr int kChunk = 64;
    int id = static_cast<int>(body_start.size());
    int m = static_cast<int>(b.size());
    body_start.push_back(static_cast<int>(first));
    body_count.push_back(m);
    body_chunk_start.push_back(static_cast<int>(chunk_start.size()));
    body_chunk_count.push_back((m + kChunk - 1) / kChunk);
    for (int k = 0; k < m; k += kChunk) {
      chunk_start.push_back(static_cast<int>(first) + k);
      chunk_count.push_back(std::min(kChunk, m - k));
      chunk_body.push_back(id);
    }
    body_stiffness.push_back(b.stiffness);
    c.push_back(b.centre);
    q.push_back(b.rotation);
    upload_bodies(c, q);
  }

  // Greedy edge colouring: no particle has two edges of one colour, so each colour's
  // constraints can be projected together at full stiffness (see kernels::cloth_stretch).
  std::vector<int> colour_edges(std::size_t N) {
    std::vector<std::uint64_t> used(N, 0);
    std::vector<int> col(edge_a.size());
    for (std::size_t e = 0; e < edge_a.size(); ++e) {
      std::uint64_t busy = used[edge_a[e]] | used[edge_b[e]];
      int c = 0;
      while (c < 64 && (busy >> c & 1u)) ++c;
      if (c == 64) throw Error("particle solver: a cloth particle has more than 63 stretch constraints");
      col[e] = c;
      used[edge_a[e]] |= std::uint64_t{1} << c, used[edge_b[e]] |= std::uint64_t{1} << c;
    }
    return col;
  }

  // Stretch edges grouped by colour (uploaded), bending constraints and triangles as CSR by
  // particle id. Stretch constraints are coloured and keep their stiffness; bending stiffness is
  // divided by the larger degree of a constraint's particles over cloth_relaxation (Macklin 2014
  // eq. 11 averaging, made symmetric so that a pair's corrections stay equal and opposite).
  void rebuild_cloth() {
    const std::size_t N = static_cast<std::size_t>(n);
    std::vector<int> bdeg(N, 0);
    for (const K::Quad& q : bends) ++bdeg[q.a], ++bdeg[q.b], ++bdeg[q.c], ++bdeg[q.d];
    auto scale = [&](int dmax) { return std::min(1.f, P.cloth_relaxation / static_cast<float>(std::max(dmax, 1))); };
    std::vector<int> col = colour_edges(N);
    const int colours = col.empty() ? 0 : *std::max_element(col.begin(), col.end()) + 1;
    colour_off.assign(static_cast<std::size_t>(colours) + 1, 0);
    for (int c : col) ++colour_off[c + 1];
    for (int c = 0; c < colours; ++c) colour_off[c + 1] += colour_off[c];
    std::vector<std::int64_t> fill(colour_off.begin(), colour_off.end() - 1);
    std::vector<int> ea(edge_a.size()), eb(edge_a.size());
    std::vector<float> len(edge_a.size()), k(edge_a.size()), lim(edge_a.size());
    strain_limited = false;
    for (std::size_t e = 0; e < edge_a.size(); ++e) {
      std::int64_t at = fill[col[e]]++;
      ea[at] = edge_a[e], eb[at] = edge_b[e], len[at] = edge_len[e], k[at] = edge_k0[e], lim[at] = edge_limit0[e];
      strain_limited = strain_limited || edge_limit0[e] > 0.f;
    }
    if (ea.empty()) ea.push_back(0), eb.push_back(0), len.push_back(0.f), k.push_back(0.f), lim.push_back(0.f);
    d_edge_a = Buffer<int>::from_host(ea, dev), d_edge_b = Buffer<int>::from_host(eb, dev);
    d_edge_len = Buffer<float>::from_host(len, dev), d_edge_k = Buffer<float>::from_host(k, dev);
    d_edge_limit = Buffer<float>::from_host(lim, dev);
    std::vector<float> bk(bends.size());
    std::vector<std::vector<int>> inc(N);
    for (std::size_t i = 0; i < bends.size(); ++i) {
      const K::Quad& q = bends[i];
      bk[i] = bend_k0[i] * scale(std::max({bdeg[q.a], bdeg[q.b], bdeg[q.c], bdeg[q.d]}));
      // The slot of id's correction, 4 b + vertex (the first vertex that is id, as before).
      for (int id : {q.a, q.b, q.c, q.d})
        inc[id].push_back(4 * static_cast<int>(i) + (q.a == id ? 0 : q.b == id ? 1 : q.c == id ? 2 : 3));
    }
    upload_csr(inc, bend_off, bend_list);
    std::vector<std::vector<int>> tinc(N);
    for (std::size_t i = 0; i < tris.size(); ++i)
      for (int id : {tris[i].x, tris[i].y, tris[i].z}) tinc[id].push_back(static_cast<int>(i));
    upload_csr(tinc, tri_off, tri_list);
    d_bends = Buffer<K::Quad>::from_host(bends, dev), d_bend_rest = Buffer<float>::from_host(bend_rest, dev);
    d_bend_k = Buffer<float>::from_host(bk, dev), d_tris = Buffer<int3>::from_host(tris, dev);
    bend_delta = Buffer<vec3>(std::max<std::int64_t>(1, 4 * static_cast<std::int64_t>(bends.size())), dev);
  }

  void upload_csr(const std::vector<std::vector<int>>& lists, Buffer<int>& off, Buffer<int>& items) {
    std::vector<int> o(lists.size() + 1, 0), it;
    for (std::size_t i = 0; i < lists.size(); ++i) {
      o[i + 1] = o[i] + static_cast<int>(lists[i].size());
      it.insert(it.end(), lists[i].begin(), lists[i].end());
    }
    if (it.empty()) it.push_back(0);
    off = Buffer<int>::from_host(o, dev), items = Buffer<int>::from_host(it, dev);
  }

  // `spawn`, `entry`: the spawn entry the batch comes from (index -1 and null: none), recorded
  // with the object; a rigid body's mesh is made from the entry.
  std::int64_t add_batch(const ParticleBatch& b, int spawn = -1, const SpawnParams* entry = nullptr) {
    const std::int64_t m = b.size(), first = n;
    if (m == 0) return first;
    ++generation;
    ensure_capacity(n + m);
    std::uint32_t flags = 0;
    if (b.kind == ParticleBatch::kFluid) flags = phase::kFluid;
    if (b.kind == ParticleBatch::kRigid) {
      if (body_start.size() >= phase::kGroupMask) throw Error("particle solver: too many rigid bodies (max 2^24)");
      flags = phase::kRigid | static_cast<std::uint32_t>(body_start.size());
    }
    if (b.kind == ParticleBatch::kCloth)
      flags = phase::kCloth | static_cast<std::uint32_t>(cloth_groups++) | (b.self_collide ? phase::kSelfCollide : 0u);
    upload_at(x, first, b.x), upload_at(v, first, b.v), upload_at(w, first, b.inv_mass);
    upload_at(phase, first, std::vector<std::uint32_t>(static_cast<std::size_t>(m), flags));
    std::vector<int> ids(static_cast<std::size_t>(m));
    for (std::int64_t i = 0; i < m; ++i) ids[static_cast<std::size_t>(i)] = static_cast<int>(first + i);
    upload_at(slot_id, first, ids);  // new particles: slot = id, after every slot in use
    ++state_version;
    if (!b.rest.empty()) upload_at(rest, first, b.rest);
    if (!b.rsdf.empty()) upload_at(rsdf, first, b.rsdf);
    n += m;
    if (b.kind == ParticleBatch::kFluid) n_fluid += m;
    if (b.kind == ParticleBatch::kRigid) {
      n_rigid += m;
      add_body(b, first);
      objects.bodies.push_back({first, m, spawn, b.rest, entry ? body_mesh(*entry, P) : nullptr});
    }
    if (b.kind == ParticleBatch::kCloth) {
      n_cloth += m;
      const int o = static_cast<int>(first);
      for (std::size_t e = 0; e < b.edge_a.size(); ++e) {
        edge_a.push_back(b.edge_a[e] + o), edge_b.push_back(b.edge_b[e] + o);
        edge_len.push_back(b.edge_len[e]), edge_k0.push_back(b.stretch_k), edge_limit0.push_back(b.max_strain);
      }
      for (std::size_t i = 0; i < b.bends.size(); ++i) {
        const K::Quad& q = b.bends[i];
        bends.push_back({q.a + o, q.b + o, q.c + o, q.d + o});
        bend_rest.push_back(b.bend_rest[i]), bend_k0.push_back(b.bend_k);
      }
      ClothSheet sheet{first, m, spawn, {}};
      for (const int3& t : b.tris) sheet.triangles.push_back({t.x + o, t.y + o, t.z + o});
      tris.insert(tris.end(), sheet.triangles.begin(), sheet.triangles.end());
      objects.cloths.push_back(std::move(sheet));
      rebuild_cloth();
    }
    return first;
  }

  void run_emitters(float dt) {
    for (solver_state::Emitter& e : emitters) {
      if (e.s.duration > 0.f && time >= e.start + e.s.duration) continue;
      // A layer leaves the nozzle each time the jet has advanced one diameter, as far as the
      // rate allows.
      e.distance += length(e.s.velocity) * dt;
      e.budget += e.s.rate * dt;
      ParticleBatch layer = make_emitter_layer(e.s, P);
      while (e.distance >= P.particle_diameter && e.budget >= static_cast<double>(layer.size())) {
        e.distance -= P.particle_diameter;
        e.budget -= static_cast<double>(layer.size());
        if (n + layer.size() > P.max_particles) {
          if (emitter_dropped == 0)
            spdlog::warn(
                "emitter at ({:.2f}, {:.2f}, {:.2f}): solver.max_particles = {} reached at t = {:.3f} s; its "
                "further layers are dropped (the total is in the physics summary)",
                e.s.position.x, e.s.position.y, e.s.position.z, P.max_particles, time);
          emitter_dropped += layer.size();
          continue;
        }
        // Each layer starts where the previous would be now, so the stream stays evenly spaced.
        for (vec3& p : layer.x) p += normalize(e.s.velocity) * static_cast<float>(e.distance);
        add_batch(layer);
        layer = make_emitter_layer(e.s, P);
      }
      // A rate below what the jet speed asks for spaces the layers further apart instead.
      e.distance = std::min(e.distance, static_cast<double>(P.particle_diameter));
    }
  }

  // A spawn whose particles start inside the scene's solid (in a wall, or outside the synthetic
  // room: the room's SDF is solid there) is pushed to the nearest surface by the first collision;
  // one far outside the scanned scene falls with nothing to land on. Either is said once, with the
  // number of particles, instead of happening silently.
  void report_placement(const SpawnParams& s, const std::vector<vec3>& x) {
    if (x.empty()) return;
    kernels::SceneSdf host_sdf = sdf;
    host_sdf.grid = nullptr;  // the sampled TSDF lives on the device; the primitives and the room suffice
    std::int64_t solid = 0, far = 0;
    const bool scanned = n_static > 0;
    if (scanned) find_static_bounds();
    const vec3 lo = static_lo, hi = static_hi;
    const float m = kScanMargin;
    for (vec3 p : x) {
      if (host_sdf.active() && kernels::scene_sdf(host_sdf, p).d < 0.f) ++solid;
      if (scanned &&
          (p.x < lo.x - m || p.y < lo.y - m || p.z < lo.z - m || p.x > hi.x + m || p.y > hi.y + m || p.z > hi.z + m))
        ++far;
    }
    const std::string what = enum_name(s.kind) + std::string(" at (") + format_vec(s.position) + ")";
    if (solid > 0)
      spdlog::warn(
          "spawn {}: {} of {} particles start inside the scene's solid (in a wall or object, or outside the "
          "room); the first collision moves them to the nearest surface. Check the spawn position (world "
          "frame: README, Usage)",
          what, solid, x.size());
    if (far > 0)
      spdlog::warn(
          "spawn {}: {} of {} particles start more than {} m outside the scanned scene (x {:.2f}..{:.2f}, y "
          "{:.2f}..{:.2f}, z {:.2f}..{:.2f}): there is nothing there for them to land on",
          what, far, x.size(), kScanMargin, lo.x, hi.x, lo.y, hi.y, lo.z, hi.z);
  }

  // An emitter puts out one layer each time its jet has moved one diameter: at most
  // layer * |velocity| / diameter particles a second, whatever its rate asks for.
  void report_emitter_rate(const SpawnParams& s) {
    const double layer = static_cast<double>(make_emitter_layer(s, P).size());
    const double most = layer * length(s.velocity) / P.particle_diameter;
    if (s.rate <= most * (1.0 + 1e-6)) return;
    spdlog::warn(
        "spawn emitter at ({}): rate {} particles/s is more than its jet carries ({} particles a layer, a "
        "layer per {} m travelled at {:.3g} m/s: {:.0f} particles/s); it emits {:.0f}/s. Raise velocity or "
        "nozzle_radius for more",
        format_vec(s.position), s.rate, layer, P.particle_diameter, length(s.velocity), most, most);
  }

  static std::string format_vec(vec3 v) {
    char buf[96];
    std::snprintf(buf, sizeof buf, "%.2f, %.2f, %.2f", v.x, v.y, v.z);
    return buf;
  }

  void spawn_due() {
    schedule.spawn_due(time, gate, [&](const SpawnSchedule::Entry& e) { spawn(e.s, e.index); });
  }

  // `index`: the entry's place in the scheduled list (-1: spawned directly), kept with its object.
  std::int64_t spawn(const SpawnParams& s, int index) {
    auto placed = [&](ParticleBatch b) {
      report_placement(s, b.x);
      return add_batch(b, index, &s);
    };
    if (s.kind == SpawnKind::fluid_block) return placed(make_fluid_block(s, P));
    if (s.kind == SpawnKind::cloth) return placed(make_cloth(s, P));
    if (s.kind == SpawnKind::rigid) return placed(make_rigid(s, P));
    if (s.kind == SpawnKind::emitter) {
      report_placement(s, make_emitter_layer(s, P).x);
      report_emitter_rate(s);
      emitters.push_back({s, time, P.particle_diameter, 0.0});
      return n;
    }
    throw ConfigError("spawn: unknown kind '" + std::string(enum_name(s.kind)) +
                      "' (expected fluid_block, emitter, cloth or rigid)");
  }

  // The scene particles' bounding box: one download of them, on the first spawn after they changed
  // (a spawn's placement report is rare; the steps never need it).
  void find_static_bounds() {
    if (static_bounds_known) return;
    static_lo = {1e30f, 1e30f, 1e30f}, static_hi = {-1e30f, -1e30f, -1e30f};
    std::vector<vec3> pts(static_cast<std::size_t>(n_static));
    memory::copy(pts.data(), Device::CPU, static_points.data(), dev, sizeof(vec3) * pts.size());
    for (vec3 p : pts) static_lo = vmin(static_lo, p), static_hi = vmax(static_hi, p);
    static_bounds_known = true;
  }

  // Appends n points at src (on device src_dev) to the scene particles, in order.
  void append_static(const vec3* src, Device src_dev, std::int64_t n) {
    if (n <= 0) return;
    grow(static_points, n_static + n, n_static, dev);
    memory::copy(static_points.data() + n_static, dev, src, src_dev, sizeof(vec3) * static_cast<std::size_t>(n));
    n_static += n;
    static_bounds_known = false;
    rebuild_static();
  }

  // Replaces the colliders by the n points at src (on device src_dev).
  void replace_colliders(const vec3* src, Device src_dev, std::int64_t n) {
    if (n == 0 && n_colliders == 0) return;
    collider_points.reserve_discard(n, dev);
    memory::copy(collider_points.data(), dev, src, src_dev, sizeof(vec3) * static_cast<std::size_t>(n));
    n_colliders = n;
    ++generation;
    rebuild_static();
  }

  void rebuild_static() {
    ++generation;
    const std::int64_t ns = static_count();
    if (ns == 0) return;
    int sb = K::GridSpec::bits_for(ns);
    sgrid = K::GridSpec::for_radius(std::max(P.fluid_smoothing * P.particle_diameter, 1.5f * P.particle_diameter), sb);
    std::int64_t cells = std::int64_t{1} << (3 * sb);
    // The scene's points, then the colliders' (device to device), in buffers kept between calls:
    // live mode rebuilds this grid every frame with the new colliders.
    Buffer<vec3>& raw = static_raw;
    Buffer<std::uint32_t>& keys = static_keys;
    Buffer<int>& idx = static_idx;
    raw.reserve_discard(ns, dev), keys.reserve_discard(ns, dev), idx.reserve_discard(ns, dev);
    stat.reserve_discard(ns, dev), scell_start.reserve_discard(cells + 1, dev);
    memory::copy(raw.data(), dev, static_points.data(), dev, sizeof(vec3) * static_cast<std::size_t>(n_static));
    memory::copy(raw.data() + n_static, dev, collider_points.data(), dev,
                 sizeof(vec3) * static_cast<std::size_t>(n_colliders));
    with_exec(dev, [&]<class E>(const E& ex) {
      using Grid = K::NeighbourGrid<E>;
      Grid::cell_keys(ex, raw.data(), ns, sgrid, keys.data(), idx.data());
      Grid::sort_cells(ex, keys.data(), idx.data(), ns, 3 * sb);
      Grid::gather_vec3(ex, raw.data(), idx.data(), ns, stat.data());
      Grid::cell_starts(ex, keys.data(), ns, scell_start.data(), cells);
    });
    snbr.reserve_discard(std::max<std::int64_t>(cap, 1) * (P.max_static_neighbours + 1), dev);
  }
};

ParticleSolver::ParticleSolver(const SolverParams& params, Device device)
    : impl_(std::make_unique<Impl>(params, device)) {}
ParticleSolver::~ParticleSolver() = default;

namespace {

// The first `count` elements of `points`, checked (a count over the buffer's size is a caller's bug).
void check_count(const char* what, const Buffer<vec3>& points, std::int64_t count) {
  if (count < 0 || count > points.size())
    throw Error(std::string(what) + ": " + std::to_string(count) + " points asked of a buffer of " +
                std::to_string(points.size()));
}

}  // namespace

void ParticleSolver::add_static_particles(const std::vector<vec3>& points) {
  impl_->append_static(points.data(), Device::CPU, static_cast<std::int64_t>(points.size()));
}

void ParticleSolver::add_static_particles(const Buffer<vec3>& points, std::int64_t count) {
  check_count("add_static_particles", points, count);
  impl_->append_static(points.data(), points.device(), count);
}

void ParticleSolver::clear_static_particles() {
  impl_->n_static = 0;
  impl_->static_bounds_known = false;
  ++impl_->generation;
  if (impl_->n_colliders > 0) impl_->rebuild_static();
}

void ParticleSolver::set_collider_particles(const std::vector<vec3>& points) {
  impl_->replace_colliders(points.data(), Device::CPU, static_cast<std::int64_t>(points.size()));
}

void ParticleSolver::set_collider_particles(const Buffer<vec3>& points, std::int64_t count) {
  check_count("set_collider_particles", points, count);
  impl_->replace_colliders(points.data(), points.device(), count);
}

void ParticleSolver::set_scene_sdf(const kernels::SceneSdf& sdf) {
  const float* g = impl_->sdf.grid;
  int3 dims = impl_->sdf.dims;
  vec3 origin = impl_->sdf.origin;
  float voxel = impl_->sdf.voxel;
  impl_->sdf = sdf;
  ++impl_->generation;
  impl_->sdf.grid = g, impl_->sdf.dims = dims, impl_->sdf.origin = origin, impl_->sdf.voxel = voxel;
}

void ParticleSolver::set_scene_sdf_grid(const std::vector<float>& values, int3 dims, vec3 origin, float voxel) {
  if (static_cast<std::int64_t>(values.size()) != std::int64_t{dims.x} * dims.y * dims.z || voxel <= 0.f)
    throw Error("set_scene_sdf_grid: " + std::to_string(values.size()) + " values do not fill a " +
                std::to_string(dims.x) + "x" + std::to_string(dims.y) + "x" + std::to_string(dims.z) +
                " grid with a positive voxel size");
  impl_->sdf_grid = Buffer<float>::from_host(values, impl_->dev);
  ++impl_->generation;
  impl_->sdf.grid = impl_->sdf_grid.data(), impl_->sdf.dims = dims, impl_->sdf.origin = origin,
  impl_->sdf.voxel = voxel;
}

std::int64_t ParticleSolver::spawn(const SpawnParams& s) { return impl_->spawn(s, -1); }

void ParticleSolver::schedule(const std::vector<SpawnParams>& spawns) {
  check_spawn_capacity(spawns, impl_->P);
  impl_->schedule.add(spawns);
}

void ParticleSolver::set_spawn_gate(SpawnSchedule::Gate gate) { impl_->gate = std::move(gate); }

void ParticleSolver::spawn_next() {
  std::optional<SpawnSchedule::Entry> e = impl_->schedule.take_next();
  if (!e) return spdlog::info("spawn: every configured object is spawned already");
  spdlog::info("spawn: {} (configured for t = {:.2f} s) now", enum_name(e->s.kind), e->s.time);
  impl_->spawn(e->s, e->index);
}

std::size_t ParticleSolver::pending_spawns() const { return impl_->schedule.pending(); }

std::int64_t ParticleSolver::add_batch(const ParticleBatch& b) { return impl_->add_batch(b); }

int ParticleSolver::substeps(float dt) const {
  const SolverParams& P = impl_->P;
  if (dt < 0.f) dt = P.dt;
  double need = std::ceil(P.max_speed * dt / (P.tunnel_fraction * P.particle_diameter) - 1e-6);
  return std::max(P.substeps, static_cast<int>(std::max(need, 1.0)));
}

void ParticleSolver::step(float dt) {
  if (dt < 0.f) dt = impl_->P.dt;
  impl_->spawn_due();
  impl_->run_emitters(dt);
  impl_->advance(dt, substeps(dt));
  impl_->time += dt;
  ++impl_->steps;
}

SolverStats ParticleSolver::stats() const {
  Impl& I = *impl_;
  SolverStats s;
  s.particles = I.n, s.fluid_particles = I.n_fluid, s.cloth_particles = I.n_cloth, s.rigid_particles = I.n_rigid;
  s.rigid_bodies = static_cast<std::int64_t>(I.body_start.size());
  s.static_particles = I.n_static;
  s.collider_particles = I.n_colliders;
  s.substeps = substeps();
  s.time = I.time, s.steps = I.steps, s.emitter_dropped = I.emitter_dropped;
  // One small read: the counters the kernels keep on the device (overflow, longest lists, the
  // largest |v|^2 of the last step).
  std::vector<int> c = I.counters.to_host();
  s.neighbour_overflow = c[0], s.static_neighbour_overflow = c[1];
  s.max_neighbours_seen = c[2], s.max_static_neighbours_seen = c[3];
  if (I.n > 0) s.max_speed = std::sqrt(bits_float(c[4]));
  if (s.emitter_dropped > 0)
    spdlog::warn(
        "particle solver: emitters could not create {} particles (solver.max_particles = {} reached); raise "
        "solver.max_particles",
        s.emitter_dropped, I.P.max_particles);
  if (s.neighbour_overflow > 0 || s.static_neighbour_overflow > 0)
    spdlog::warn(
        "particle solver: {} neighbour lists and {} scene lists exceeded the cap ({} / {}); raise "
        "solver.max_neighbours / solver.max_static_neighbours",
        s.neighbour_overflow, s.static_neighbour_overflow, I.P.max_neighbours, I.P.max_static_neighbours);
  return s;
}

ParticleState ParticleSolver::download_state() const {
  Impl& I = *impl_;
  ParticleState s;
  auto cut = [&](auto v) {
    v.resize(static_cast<std::size_t>(I.n));
    return v;
  };
  if (I.n == 0) return s;
  // The slots' state, put in id order here.
  const std::vector<int> ids = cut(I.slot_id.to_host());
  const auto by_id = [&](auto slots) {
    auto out = slots;
    for (std::size_t k = 0; k < ids.size(); ++k) out[static_cast<std::size_t>(ids[k])] = slots[k];
    return out;
  };
  s.x = by_id(cut(I.x.to_host())), s.v = by_id(cut(I.v.to_host()));
  s.inv_mass = by_id(cut(I.w.to_host())), s.phase = by_id(cut(I.phase.to_host()));
  return s;
}

std::vector<RigidFrame> ParticleSolver::rigid_frames() const {
  Impl& I = *impl_;
  std::vector<RigidFrame> out;
  std::vector<vec3> c = I.body_c.to_host();
  std::vector<vec4> q = I.body_q.to_host();
  for (std::size_t b = 0; b < I.body_start.size(); ++b) out.push_back({c[b], q[b], I.body_start[b], I.body_count[b]});
  return out;
}

const SceneObjects& ParticleSolver::objects() const { return impl_->objects; }
const vec3* ParticleSolver::device_positions() const {
  impl_->copy_to_id_order();
  return impl_->x_id.data();
}
const std::uint32_t* ParticleSolver::device_phases() const {
  impl_->copy_to_id_order();
  return impl_->phase_id.data();
}
std::int64_t ParticleSolver::size() const { return impl_->n; }
const SolverParams& ParticleSolver::params() const { return impl_->P; }
Device ParticleSolver::device() const { return impl_->dev; }
float ParticleSolver::fluid_rest_density() const { return impl_->rho0; }

std::vector<float> ParticleSolver::fluid_density_ratio() const {
  Impl& I = *impl_;
  if (I.n == 0) return {};
  I.prepare_grid();
  K::SimViews S = I.views(I.P.dt);
  S.c.dt = 0.f, S.c.max_speed = 1e30f;  // predicted = current positions, velocities untouched
  with_exec(I.dev, [&]<class E>(const E& ex) {
    K::NeighbourGrid<E>::predict(ex, S);
    I.build_neighbours(ex, S);
    K::Fluid<E>::prepare_constraints(ex, S);
  });
  std::vector<float> rho = I.density.to_host();
  std::vector<int> order = I.order.to_host();
  std::vector<float> out(static_cast<std::size_t>(I.n));
  for (std::int64_t s = 0; s < I.n; ++s) out[order[s]] = rho[s] / I.rho0;
  return out;
}

}  // namespace seamless
