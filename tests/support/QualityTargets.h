#pragma once

#include <gtest/gtest.h>

#include "eval/Evaluation.h"

namespace subscan::test {

/// The reconstruction quality targets of the issue, for the evaluation tests.
inline void expectQualityTargets(const EvaluationReport& report) {
    const QualityMetrics& surface = report.surface;
    EXPECT_GE(surface.coverage, 0.97);
    EXPECT_LE(surface.leakage, 0.03);
    EXPECT_LE(surface.occlusionErrorRate, 0.01);
    ASSERT_TRUE(surface.normalErrorMeanDeg.has_value());
    EXPECT_LE(*surface.normalErrorMeanDeg, 10.0);
    EXPECT_GT(surface.psnrDb, report.points1px.psnrDb);
    EXPECT_GT(surface.psnrDb, report.splats.psnrDb);
}

}  // namespace subscan::test
