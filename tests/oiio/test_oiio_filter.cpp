// The reference's downsample filter against the installed OpenImageIO's own filter table: the
// library calls OpenImageIO's resize through its module, so its width and values are checked here,
// in the test binary that links OpenImageIO as an oracle.
#include <gtest/gtest.h>

#include <OpenImageIO/filter.h>

#include <memory>
#include <string>

#include <seamcl/eval/reference.h>

using namespace seamcl;

TEST(Reference, OiioMitchellIsBCOneThirdWithWidth4) {
  // The installed OIIO's filter table: mitchell's default width is 4 (what resize uses when
  // shrinking without a width), and its values at width 4 are the B = C = 1/3 kernel at x in
  // output pixels (support radius 2), separable.
  bool found = false;
  for (int i = 0; i < OIIO::Filter2D::num_filters(); ++i) {
    const OIIO::FilterDesc& d = OIIO::Filter2D::get_filterdesc(i);
    if (std::string(d.name) == "mitchell") {
      found = true;
      EXPECT_EQ(d.width, 4.0f);
      EXPECT_EQ(d.width, kMitchellWidth);
    }
  }
  ASSERT_TRUE(found);
  std::unique_ptr<OIIO::Filter2D, void (*)(OIIO::Filter2D*)> f(OIIO::Filter2D::create("mitchell", 4, 4),
                                                                 OIIO::Filter2D::destroy);
  ASSERT_TRUE(f);
  EXPECT_TRUE(f->separable());
  for (float x = -2.5f; x <= 2.5f; x += 0.0625f) {
    EXPECT_NEAR(f->xfilt(x), mitchell_netravali(x), 1e-6) << x;
    EXPECT_NEAR((*f)(x, 0.3f), mitchell_netravali(x) * mitchell_netravali(0.3), 1e-6) << x;
  }
}

