#include "granmem/tracking/detections.hpp"

#include <gtest/gtest.h>

#include <cmath>

#include "granmem/core/error.hpp"
#include "temp_dir.hpp"

namespace granmem {
namespace {

class DetectionsFile : public testing::TempDirTest {};

Detections sample() {
  Detections d;
  d.frame = 7;
  d.length_unit = "mm";
  d.voxel_size = Eigen::Vector3d(0.05, 0.05, 0.075);
  d.source = "scan7.tif";
  d.has_axis = true;
  d.add({1.25, 2.5, 3.75}, 2.5, 0.98, false);
  d.add({10.0, 0.125, -3.0}, 2.4, 0.5, true);
  d.axis.row(0) << 0, 0.6, 0.8;
  d.axis_quality[0] = 0.9;
  d.axis_error[0] = 0.0125;
  d.position_error.row(0) << 0.0025, 0.003, 0.005;
  d.hole_contact[1] = 1;
  return d;
}

void expect_same(const Detections& a, const Detections& b) {
  EXPECT_EQ(a.frame, b.frame);
  EXPECT_EQ(a.length_unit, b.length_unit);
  EXPECT_EQ(a.position, b.position);
  EXPECT_EQ(a.radius, b.radius);
  EXPECT_EQ(a.quality, b.quality);
  EXPECT_EQ(a.edge, b.edge);
  ASSERT_EQ(a.has_axis, b.has_axis);
  EXPECT_EQ(a.axis.row(0), b.axis.row(0));
  EXPECT_TRUE(b.axis.row(1).array().isNaN().all());  // not seen stays NaN
  EXPECT_EQ(a.axis_quality[0], b.axis_quality[0]);
  EXPECT_EQ(a.axis_error[0], b.axis_error[0]);
  EXPECT_TRUE(std::isnan(b.axis_error[1]));
  EXPECT_EQ(a.position_error.row(0), b.position_error.row(0));
  EXPECT_TRUE(b.position_error.row(1).array().isNaN().all());
  EXPECT_EQ(a.hole_contact, b.hole_contact);
}

TEST_F(DetectionsFile, Hdf5AndCsvRoundTripsAreExact) {
  const Detections d = sample();
  write_detections(d, path("det.h5"));
  const Detections h = read_detections(path("det.h5"));
  expect_same(d, h);
  ASSERT_TRUE(h.voxel_size.has_value());
  EXPECT_EQ(*h.voxel_size, *d.voxel_size);
  EXPECT_EQ(h.source, "scan7.tif");
  write_detections(d, path("det.csv"));
  expect_same(d, read_detections(path("det.csv")));
}

TEST_F(DetectionsFile, AnOlderTableWithoutStandardErrorsReadsThemAsUnknown) {
  write_text(path("old.csv"),
             "frame,particle,x,y,z,radius,quality,edge,ax,ay,az,axis_quality,hole_contact\n"
             "0,0,1,2,3,2.5,0.9,0,0,0,1,0.8,0\n");
  const Detections d = read_detections(path("old.csv"));
  ASSERT_EQ(d.size(), 1u);
  EXPECT_TRUE(d.position_error.array().isNaN().all());
  ASSERT_EQ(d.axis_error.size(), 1u);
  EXPECT_TRUE(std::isnan(d.axis_error[0]));
}

TEST_F(DetectionsFile, TrackpysOneStaticErrorIsTheSameOnEachAxis) {
  write_text(path("trackpy.csv"),
             "frame,particle,x,y,z,radius,quality,edge,ep\n0,0,1,2,3,2.5,0.9,0,0.125\n");
  const Detections d = read_detections(path("trackpy.csv"));
  EXPECT_EQ(Eigen::Vector3d(d.position_error.row(0).transpose()), Eigen::Vector3d::Constant(0.125));
}

TEST_F(DetectionsFile, AFileWithoutDetectionsIsRefused) {
  write_text(path("other.csv"), "frame,particle,x,y\n0,0,1,2\n");
  EXPECT_THROW(read_detections(path("other.csv")), Error);
  EXPECT_THROW(read_detections(path("missing.h5")), Error);
}

}  // namespace
}  // namespace granmem
