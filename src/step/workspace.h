// Workspace: grid and per-particle scratch, rebuilt every step and never saved (STYLE H.4).
#pragma once
#include <vector>

#include "contact/contact.h"
#include "grid/sparse_grid.h"
#include "stabilize/antilocking.h"
#include "transfer/transfer.h"

namespace surge {

struct Workspace {
  SparseGrid grid;
  std::vector<Mat3> velocity_gradient;  // L_p [1/s]        written by GridToParticle / VelocityGradient
  std::vector<Vec3> x_new;              // x_{n+1} [m] (MUSL) written by GridToParticle
  std::vector<uint8_t> exit_flag;       // scratch of DomainExit and ReorderParticles
  std::vector<uint32_t> reorder;        // scratch of ReorderParticles
  AntiLockingScratch antilocking;       // node sums of AntiLocking
  ContactScratch contact;               // broad phase and partial sums of the obstacle contact
};

}  // namespace surge
