// `analytic eval`: one case of JSON in, one JSON object of shader outputs out.
#pragma once

#include <nlohmann/json.hpp>

#include <iosfwd>
#include <stdexcept>
#include <string>

namespace pine::analytic::tool {

/// A case that cannot be evaluated, naming the offending key.
class CaseError : public std::runtime_error {
public:
    CaseError(std::string key, const std::string& problem)
        : std::runtime_error(problem), mKey(std::move(key)) {}
    const std::string& key() const { return mKey; }

private:
    std::string mKey;
};

/// Evaluates one case (keys in docs/analytic-tool.md). Throws CaseError on bad input.
nlohmann::json evaluateCase(const nlohmann::json& input);

/// Reads JSON Lines from `in`, writes one JSON object per line to `out`. Blank lines are
/// skipped. On the first bad line: one line on `err` naming its number and key, return 2.
int runEval(std::istream& in, std::ostream& out, std::ostream& err);

}  // namespace pine::analytic::tool
