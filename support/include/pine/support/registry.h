// A table of named implementations of one interface (a bough law, an extinction law): filled
// in one place, looked up by the name a user gave, so that an unknown name is the user's error.
#pragma once

#include "pine/support/input_error.h"

#include <memory>
#include <string>
#include <utility>
#include <vector>

namespace pine {

template <class Interface>
class Registry {
public:
    /// `kind` names what is registered, in errors: "unknown bough law 'x' (known: linear)".
    explicit Registry(std::string kind) : mKind(std::move(kind)) {}

    Registry& add(std::string name, std::unique_ptr<Interface> item)
    {
        mEntries.push_back({std::move(name), std::move(item)});
        return *this;
    }

    /// The entry registered as `name`; throws InputError naming the registered ones.
    const Interface& get(const std::string& name) const
    {
        for (const Entry& e : mEntries) {
            if (e.name == name) return *e.item;
        }
        std::string known;
        for (const Entry& e : mEntries) known += (known.empty() ? "" : ", ") + e.name;
        throw InputError("unknown " + mKind + " '" + printable(name) + "' (known: " + known + ")");
    }

    /// The names, in registration order (the first is the default).
    std::vector<std::string> names() const
    {
        std::vector<std::string> out;
        for (const Entry& e : mEntries) out.push_back(e.name);
        return out;
    }

private:
    struct Entry {
        std::string name;
        std::unique_ptr<Interface> item;
    };
    std::string mKind;
    std::vector<Entry> mEntries;
};

/// A choice between two names (render.bark, render.layer_correlation): `on` (true, the
/// default) or `off`.
inline Registry<const bool> namedSwitch(std::string kind, std::string on, std::string off)
{
    Registry<const bool> r(std::move(kind));
    r.add(std::move(on), std::make_unique<const bool>(true));
    r.add(std::move(off), std::make_unique<const bool>(false));
    return r;
}

}  // namespace pine
