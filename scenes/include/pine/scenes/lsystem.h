// The L-system of a species: its alphabet and its parallel rewriting (Prusinkiewicz &
// Lindenmayer, "The Algorithmic Beauty of Plants", ch. 1). The turtle that draws the result is
// in growTree (tree.h).
#pragma once

#include <cstddef>
#include <map>
#include <string>

namespace pine::scenes {

/// Longest string an L-system may expand to: a paper fir needs about 2,000 symbols, so this
/// leaves room for trees a thousand times larger and stops a runaway rule early.
inline constexpr std::size_t kMaxLSystemLength = 4'000'000;

/// A symbol the turtle acts on: F [ ] + - & ^ / \ !
bool isTurtleSymbol(char c);
/// A symbol allowed in an axiom or a rule: a turtle symbol or a letter (letters other than F
/// are non-terminals the turtle ignores).
bool isLSystemSymbol(char c);

/// Length of the string after `iterations` rewrites, without building it; saturates at
/// `limit` + 1, so a runaway rule costs nothing to detect.
std::size_t expandedLength(const std::string& axiom, const std::map<char, std::string>& rules,
                           int iterations, std::size_t limit = kMaxLSystemLength);

/// Default of a species' lsystem.max_segments: the F symbols (segments, each a branch that may
/// bear a bough) one tree may grow. A paper fir has about 350; render time grows faster than
/// the segments where their boughs crowd one another (a bushy rule of 131,072 segments rendered
/// for minutes), so a larger tree is asked for knowingly.
inline constexpr std::size_t kDefaultMaxSegments = 50'000;

/// How many symbols among `counted` the string holds after `iterations` rewrites, without
/// building it; saturates at `limit` + 1.
std::size_t expandedCount(const std::string& axiom, const std::map<char, std::string>& rules,
                          int iterations, const std::string& counted, std::size_t limit);

/// The string after `iterations` parallel rewrites of `axiom` (a symbol without a rule is
/// copied). Throws std::length_error past `limit` symbols.
std::string expandLSystem(const std::string& axiom, const std::map<char, std::string>& rules,
                          int iterations, std::size_t limit = kMaxLSystemLength);

}  // namespace pine::scenes
