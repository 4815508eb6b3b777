// Particle storage: structure of arrays (STYLE H.4). Index p is the same particle in every array.
// SI units, tension positive (Mast 2013 convention).
#pragma once
#include <algorithm>
#include <array>
#include <cstddef>
#include <cstdint>
#include <vector>

#include "core/math.h"

namespace surge {

// Per-particle history scalars of the plastic models. The meaning of each slot is fixed per
// material model, in the model's header (materials/j2.h) and in docs/materials.md; models
// without history leave all slots at zero. Slot kPlasticStrainSlot is the equivalent plastic
// strain [-] in every plastic model (results field `plastic_strain`).
inline constexpr int kHistorySlots = 8;
inline constexpr int kPlasticStrainSlot = 0;
using History = std::array<Real, kHistorySlots>;

// Per-particle history scalars stored with a run-wide stride: the most slots any material of the
// run uses (ParticleLayout::history_slots), so a smooth-cap Drucker-Prager run stores 3 scalars per
// particle, not kHistorySlots (performance issue: bytes per particle). Row p is
// [p * stride, (p + 1) * stride); the models read and write a full History copy of it
// (UpdateStress), whose slots at and above the stride they leave at zero.
class HistoryArray {
 public:
  Real* operator[](size_t p) { return data_.data() + p * size_t(stride_); }
  const Real* operator[](size_t p) const { return data_.data() + p * size_t(stride_); }
  size_t size() const { return stride_ > 0 ? data_.size() / size_t(stride_) : 0; }
  int stride() const { return stride_; }
  size_t capacity() const { return data_.capacity(); }  // values allocated (memory accounting)
  Real* data() { return data_.data(); }
  const Real* data() const { return data_.data(); }
  // n rows of `stride` zeros (stride 0: empty); rows kept where both sizes have them.
  void Resize(size_t n, int stride) {
    if (stride != stride_) {
      std::vector<Real> next(n * size_t(stride), 0.0);
      const size_t rows = std::min(n, size());
      const int common = std::min(stride, stride_);
      for (size_t p = 0; p < rows; ++p)
        for (int k = 0; k < common; ++k) next[p * size_t(stride) + size_t(k)] = (*this)[p][k];
      data_.swap(next);
      stride_ = stride;
    } else {
      data_.resize(n * size_t(stride), 0.0);
    }
  }
  // The row as a full History (slots at and above the stride are zero), and back.
  History Get(size_t p) const {
    History h{};
    for (int k = 0; k < stride_; ++k) h[size_t(k)] = (*this)[p][k];
    return h;
  }
  void Set(size_t p, const History& h) {
    for (int k = 0; k < stride_; ++k) (*this)[p][k] = h[size_t(k)];
  }
  void CopyRow(size_t to, size_t from) {
    for (int k = 0; k < stride_; ++k) (*this)[to][k] = (*this)[from][k];
  }
  // Exchanges the rows with `rows` (size() * stride() values): the reorder stage's permuted copy.
  void Swap(std::vector<Real>& rows) { data_.swap(rows); }

 private:
  std::vector<Real> data_;
  int stride_ = kHistorySlots;
};

// Which of the optional particle arrays a run stores. An array a run does not use stays empty
// (size 0) in every operation, so it costs no memory (performance issue: bytes per particle).
// The scene builder derives the layout from the materials and tractions (ParticleLayoutFor); the
// default, every array, is what tests and the single-point material driver use.
struct alignas(8) ParticleLayout {
  bool affine = true;     // C: APIC only
  bool strain = true;     // accumulated small strain: read by linear_elastic only
  bool elastic_b = true;  // b^e: the elastoplastic (Hencky) models
  bool history = true;    // history slots: the plastic models and the yield-stress fluids
  bool ext_force = true;  // particle tractions
  // History scalars per particle when `history` is set: the largest slot count of the run's
  // models (HistorySlotsFor), at most kHistorySlots.
  int history_slots = kHistorySlots;
};

// The per-particle scratch arrays a run's step pipeline fills (Workspace, AntiLockingScratch),
// and the optional node arrays of the grid (SparseGrid);
// StepScratchFor (step/step.h) derives it from the Model, as MakePipeline does;
// BytesPerParticle (scene/memory_estimate.h) counts it. The default, every
// array, is an upper bound.
struct StepScratch {
  bool velocity_gradient = true;  // L_p: every pipeline but USL with the update fused into G2P
  bool x_n = true;                // x_new: MUSL, and USL with anti-locking
  bool theta = true;              // volumetric anti-locking (AS1) and strain smoothing: theta_p
  bool tensor = true;             // full-tensor anti-locking or its stress averaging: tensor, ok
  bool inv_stretch = true;        // full-tensor anti-locking of the strain: (b^tr)^(-1/2)
  bool theta_bar = true;          // hybrid control volumes: the node-projected trace
  bool shift = true;              // particle shifting: the shift of each particle
  // Grid nodes (BytesPerBlock):
  bool node_reaction = true;      // SparseGrid::reaction: force sensors only
  bool node_momentum = true;      // a second buffer for p_i beside v_{i,n}: MUSL's re-map only
};

// Design: material history lives in Particles (rather than in per-model SoA arrays) so that
// reordering, compaction and checkpoints need no per-model code: when a run has a plastic model,
// every particle carries one b^e (48 bytes) and the run's history slots (8 bytes each: 3 for the
// smooth-cap Drucker-Prager, 8 for the traditional one); otherwise neither array is allocated
// (ParticleLayout). The elastic and Newtonian fluid updates never read or write them.
struct Particles {
  ParticleLayout layout;  // which optional arrays (C, strain, elastic_b, history, ext_force) are held
  // --- State: advanced by Step(), saved in checkpoints. ---
  std::vector<Vec3> x;       // position [m]                      written by GridToParticle
  std::vector<Vec3> v;       // velocity [m/s]                    written by GridToParticle
  std::vector<Mat3> C;       // APIC affine velocity [1/s]        written by GridToParticle (APIC)
                             //   (optional: layout.affine)
  std::vector<Mat3> F;       // deformation gradient [-]          written by UpdateDeformation
  std::vector<SymMat3> stress;  // Cauchy stress [Pa], 6 components  written by UpdateStress
  std::vector<Mat3> strain;  // accumulated small strain [-]      written by UpdateStress
                             //   (optional: layout.strain, linear_elastic only)
  // Material history (optional: layout.elastic_b / layout.history, plastic models only).
  std::vector<SymMat3> elastic_b;  // elastic left Cauchy-Green b^e = F^e F^eT [-] (Mast 2013
                                   // (3.30)), symmetric: 6 components  written by UpdateStress
  HistoryArray history;  // model-defined scalars, units per slot (see kHistorySlots), stride
                         // layout.history_slots                written by UpdateStress
  // --- Constant: set by the scene builder, never written by Step(). ---
  std::vector<Real> mass;         // [kg]
  std::vector<Real> volume0;      // reference volume [m^3]
  std::vector<Vec3> ext_force;    // particle traction force t*A_p [N] (Mast 2013 App. B.2.9)
                                  //   (optional: layout.ext_force)
  std::vector<int32_t> material;  // index into Model::materials
  std::vector<int32_t> body;      // index into Model::bodies
  std::vector<int64_t> id;        // seeding order, stable across removals

  size_t size() const { return x.size(); }

  // Resizes every array the layout holds; the others stay empty.
  void Resize(size_t n) {
    x.resize(n);
    v.resize(n);
    C.resize(layout.affine ? n : 0);
    F.resize(n);
    stress.resize(n);
    strain.resize(layout.strain ? n : 0);
    elastic_b.resize(layout.elastic_b ? n : 0, Mat3::Identity());
    history.Resize(layout.history ? n : 0, layout.history ? layout.history_slots : 0);
    mass.resize(n);
    volume0.resize(n);
    ext_force.resize(layout.ext_force ? n : 0);
    material.resize(n);
    body.resize(n);
    id.resize(n);
  }

  // Copies particle `from` into slot `to` (used by stable compaction and sorting).
  void Move(size_t to, size_t from) {
    x[to] = x[from];
    v[to] = v[from];
    if (layout.affine) C[to] = C[from];
    F[to] = F[from];
    stress[to] = stress[from];
    if (layout.strain) strain[to] = strain[from];
    if (layout.elastic_b) elastic_b[to] = elastic_b[from];
    if (layout.history) history.CopyRow(to, from);
    mass[to] = mass[from];
    volume0[to] = volume0[from];
    if (layout.ext_force) ext_force[to] = ext_force[from];
    material[to] = material[from];
    body[to] = body[from];
    id[to] = id[from];
  }
};

// Particles is the layout and these 14 arrays: checkpoint.cpp and reorder.cpp handle each one, and
// assert this so that a new array is added there too.
inline constexpr size_t kParticleArrays = 14;
inline constexpr size_t kParticlesSize = sizeof(ParticleLayout) +
                                         (kParticleArrays - 1) * sizeof(std::vector<Real>) +
                                         sizeof(HistoryArray);

}  // namespace surge
