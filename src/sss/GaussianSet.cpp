#include "sss/GaussianSet.h"

#include <algorithm>
#include <cmath>
#include <numbers>

#include <nlohmann/json.hpp>

namespace subscan {

std::array<double, 3> GaussianSet::evaluate(double radiusMm) const {
    std::array<double, 3> sum{};
    for (const Gaussian& term : gaussians) {
        if (term.varianceMm2 <= 0.0) {
            continue;
        }
        const double g = std::exp(-radiusMm * radiusMm / (2.0 * term.varianceMm2)) /
                         (2.0 * std::numbers::pi * term.varianceMm2);
        for (int c = 0; c < 3; ++c) {
            sum[c] += term.weight[c] * g;
        }
    }
    return sum;
}

std::array<double, 3> GaussianSet::weightSums() const {
    std::array<double, 3> sum{};
    for (const Gaussian& term : gaussians) {
        for (int c = 0; c < 3; ++c) {
            sum[c] += term.weight[c];
        }
    }
    return sum;
}

double GaussianSet::largestVarianceMm2() const {
    double largest = 0.0;
    for (const Gaussian& term : gaussians) {
        largest = std::max(largest, term.varianceMm2);
    }
    return largest;
}

nlohmann::json gaussiansJson(const GaussianSet& set) {
    nlohmann::json terms = nlohmann::json::array();
    for (const Gaussian& term : set.gaussians) {
        terms.push_back({{"variance_mm2", term.varianceMm2}, {"weight", term.weight}});
    }
    return terms;
}

GaussianSet gaussiansFromJson(const nlohmann::json& terms) {
    GaussianSet set;
    for (const nlohmann::json& term : terms) {
        set.gaussians.push_back({term.at("variance_mm2").get<double>(),
                                 term.at("weight").get<std::array<double, 3>>()});
    }
    return set;
}

}  // namespace subscan
