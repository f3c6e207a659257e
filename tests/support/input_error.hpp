#pragma once
// input_error(f): runs f, requires that it throws an InputError, and returns it for inspection.
#include <catch2/catch.hpp>

#include <stdexcept>

#include "core/error.hpp"

namespace efdem::test {

template <class F>
InputError input_error(F&& f) {
    try {
        f();
    } catch (const InputError& e) {
        return e;
    }
    FAIL("expected an InputError");
    throw std::logic_error("unreachable");
}

}  // namespace efdem::test
