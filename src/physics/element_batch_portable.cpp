// The portable element batch body: element_batch_body.hpp compiled for the build's baseline target. It
// runs on every CPU and is the reference the other sets are tested against
// (tests/unit/physics/fem/element_kernels.cpp).
#define BINBCSR_ELEMENT_SET portable
#include "physics/element_batch_body.hpp"

physics::ElementBatchBody physics::element_batch_portable() { return &kernels::batch::run_batches; }
