// The `# device` comment of a recording's header (formats/recording_header.hpp): what gyrod
// writes reads back, other comments and unknown keys are skipped, bad values name the line.
#include <gtest/gtest.h>

#include <string>

#include "formats/recording_csv.hpp"
#include "formats/recording_header.hpp"

using namespace gyrod::recording;

TEST(RecordingHeader, WhatGyrodWritesReadsBack) {
  const std::string comment = acquisitionHeaderComment(4, 0, 50.0, 19);
  EXPECT_EQ(comment, "device dlpf_cfg=4 fs_sel=0 rate_hz=50 smplrt_div=19");
  const std::string text = "# gyrod recording, opened 2026-01-01T00:00:00Z\n# gyrod 1.0 recording of mock\n# " +
                           comment + "\nt,gx,gy,gz,temp\n0,1,2,3,25\n";
  const AcquisitionHeader h = parseAcquisitionHeader(text, "rec.csv");
  EXPECT_EQ(h.line, 3u);
  EXPECT_EQ(h.dlpf_cfg, 4);
  EXPECT_EQ(h.fs_sel, 0);
  EXPECT_EQ(h.smplrt_div, 19);
  EXPECT_EQ(h.rate_hz, 50.0);
}

TEST(RecordingHeader, NoneUnknownKeysAndCommentsAfterTheFirstSampleAreSkipped) {
  // gyrod's own order: the column line first, its header comments after it.
  const AcquisitionHeader gyrods = parseAcquisitionHeader("t,gx\n# device dlpf_cfg=4\n1.0,0.5\n", "f");
  EXPECT_EQ(gyrods.line, 2u);
  EXPECT_EQ(gyrods.dlpf_cfg, 4);
  EXPECT_EQ(parseAcquisitionHeader("t,gx\n1.0,0.5\n# device dlpf_cfg=4\n", "f").line, 0u);
  EXPECT_EQ(parseAcquisitionHeader("1.0,0.5\n# device dlpf_cfg=4\n", "f").line, 0u);
  EXPECT_FALSE(parseAcquisitionHeader("# a comment\nt,gx\n", "f").dlpf_cfg);
  const AcquisitionHeader h = parseAcquisitionHeader("# device fs_sel=2 future=7\r\nt,gx\n", "f");
  EXPECT_EQ(h.fs_sel, 2);
  EXPECT_FALSE(h.dlpf_cfg);
}

TEST(RecordingHeader, BadValuesNameFileLineKeyAndValue) {
  auto message = [](const std::string& text) {
    try {
      parseAcquisitionHeader(text, "rec.csv");
    } catch (const RecordingError& e) {
      return std::string(e.what());
    }
    return std::string("(accepted)");
  };
  EXPECT_EQ(message("# x\n# device dlpf_cfg=7\n"), "rec.csv:2: device header: dlpf_cfg='7' is not an integer 0..6");
  EXPECT_EQ(message("# device fs_sel=a\n"), "rec.csv:1: device header: fs_sel='a' is not an integer 0..3");
  EXPECT_EQ(message("# device rate_hz=-5\n"), "rec.csv:1: device header: rate_hz='-5' is not a positive number");
  EXPECT_EQ(message("# device dlpf_cfg\n"), "rec.csv:1: device header: 'dlpf_cfg' is not key=value");
  EXPECT_EQ(message("# device dlpf_cfg=4 rate_hz=50 smplrt_div=9\n"),
            "rec.csv:1: device header: rate_hz=50 is not 1000 Hz / (1 + smplrt_div=9) = 100 Hz");
}
