#include "pine/scenes/lsystem.h"

#include <cctype>
#include <stdexcept>
#include <string_view>

namespace pine::scenes {

bool isTurtleSymbol(char c)
{
    return std::string_view("F[]+-&^/\\!").find(c) != std::string_view::npos;
}

bool isLSystemSymbol(char c)
{
    return isTurtleSymbol(c) || std::isalpha(static_cast<unsigned char>(c));
}

namespace {

// The count of symbols after `iterations` rewrites, where a symbol left as it is counts
// base[c]; saturates at limit + 1. count_k(c) is the count symbol c grows to in k rewrites.
std::size_t expandedTotal(const std::string& axiom, const std::map<char, std::string>& rules,
                          int iterations, const std::size_t (&base)[256], std::size_t limit)
{
    std::size_t count[256];
    for (int c = 0; c < 256; ++c) count[c] = base[c];
    const auto saturated = [limit](std::size_t a, std::size_t b) {
        // a + b, capped at limit + 1 (either may be capped already).
        return a > limit || b > limit || a > limit - b ? limit + 1 : a + b;
    };
    for (int k = 0; k < iterations; ++k) {
        std::size_t next[256];
        for (int c = 0; c < 256; ++c) next[c] = count[c];
        for (const auto& [symbol, successor] : rules) {
            std::size_t n = 0;
            for (char s : successor) n = saturated(n, count[static_cast<unsigned char>(s)]);
            next[static_cast<unsigned char>(symbol)] = n;
        }
        for (int c = 0; c < 256; ++c) count[c] = next[c];
    }
    std::size_t n = 0;
    for (char s : axiom) n = saturated(n, count[static_cast<unsigned char>(s)]);
    return n;
}

}  // namespace

std::size_t expandedLength(const std::string& axiom, const std::map<char, std::string>& rules,
                           int iterations, std::size_t limit)
{
    std::size_t every[256];
    for (std::size_t& n : every) n = 1;
    return expandedTotal(axiom, rules, iterations, every, limit);
}

std::size_t expandedCount(const std::string& axiom, const std::map<char, std::string>& rules,
                          int iterations, const std::string& counted, std::size_t limit)
{
    std::size_t base[256] = {};
    for (char c : counted) base[static_cast<unsigned char>(c)] = 1;
    return expandedTotal(axiom, rules, iterations, base, limit);
}

std::string expandLSystem(const std::string& axiom, const std::map<char, std::string>& rules,
                          int iterations, std::size_t limit)
{
    if (expandedLength(axiom, rules, iterations, limit) > limit) {
        throw std::length_error("L-system grows past " + std::to_string(limit) + " symbols");
    }
    std::string current = axiom, next;
    for (int k = 0; k < iterations; ++k) {
        next.clear();
        for (char s : current) {
            const auto rule = rules.find(s);
            if (rule == rules.end()) {
                next += s;
            } else {
                next += rule->second;
            }
        }
        current.swap(next);
    }
    return current;
}

}  // namespace pine::scenes
