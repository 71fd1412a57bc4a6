// A grading's grains as clumps of one named template or of a mix of them (docs/clumps.md, "Specimens
// of clumps"): the templates and the solid volume fraction [-] each is to take, as the command line
// (--clump-template elongated2:0.6,sphere:0.4), the specimen file and Python give them.
#pragma once

#include <cstdint>
#include <string>
#include <utility>
#include <vector>

namespace hilldem {

// (named template, solid volume fraction [-]) pairs in the order given; empty: balls. One template
// is the list of one at fraction 1.
using ClumpMix = std::vector<std::pair<std::string, double>>;

// How far the fractions' sum may be from 1 [-].
inline constexpr double kClumpMixSumTolerance = 1e-9;

// "NAME" (the mix of one at 1) or "NAME:FRACTION,NAME:FRACTION,...". Throws InputError naming `what`
// (the option or key it came from) and the malformed part; the names and fractions are checked by
// check_clump_mix.
ClumpMix parse_clump_mix(const std::string& text, const std::string& what);
// Throws InputError naming `what` unless every name is a named template (bodies/clump_shapes.hpp;
// the message lists them), named once, every fraction in (0, 1] and their sum 1 within
// kClumpMixSumTolerance. An empty mix (balls) passes.
void check_clump_mix(const ClumpMix& mix, const std::string& what);
// The text parse_clump_mix reads back to the same mix, to the bit: "elongated2" for one template at
// 1, else "elongated2:0.6,sphere:0.4" (each fraction in the shortest form that round trips).
std::string clump_mix_text(const ClumpMix& mix);
// For logs: "elongated2" or "a mix by solid volume of elongated2 0.6, sphere 0.4".
std::string clump_mix_words(const ClumpMix& mix);

// Each grain's template, an index into the mix, for grains of the given sizes [m] (sphere-equivalent
// volume ∝ d³ times the template's volume factor f_t = V / (π d_t³/6) of its unit, 1 for the
// equal-volume size): the grains laid end to end in a random order drawn from `seed` (a stream of
// its own: the other draws of genesis are those of the single template), each taking the template
// whose share of the line its middle falls in, the shares rotated by a random offset. Every
// template's solid volume is then its fraction of the total to within the largest grain's volume
// (docs/clumps.md), with no tie between a grain's size and its template.
std::vector<std::uint32_t> assign_clump_templates(const std::vector<double>& diameters, const ClumpMix& mix,
                                                  const std::vector<double>& volume_factors, std::uint64_t seed);

}  // namespace hilldem
