// What the build has (the SEMSEGMAP_WITH_* options of CMakeLists.txt, as compile definitions of
// the libraries a test links): a test that needs a part the build left out skips with a message.
#pragma once

#include <gtest/gtest.h>

#if !defined(SEMSEGMAP_WITH_SIM) || !defined(SEMSEGMAP_WITH_TORCH) || !defined(SEMSEGMAP_WITH_PCL)
#error "link semsegmap_datasets and semsegmap_describe (or pass the SEMSEGMAP_WITH_* definitions)"
#endif

#define SEMSEGMAP_SKIP_WITHOUT_SIM() \
  if (!SEMSEGMAP_WITH_SIM) GTEST_SKIP() << "this build has no simulator (SEMSEGMAP_WITH_SIM=OFF)"

#define SEMSEGMAP_SKIP_WITHOUT_TORCH() \
  if (!SEMSEGMAP_WITH_TORCH) GTEST_SKIP() << "built without libtorch (SEMSEGMAP_WITH_TORCH=OFF)"
