#pragma once
// Where the [.validation] tests put what they measure: CSV series in $EFDEM_VALIDATION_OUT
// (default ./validation_out; scripts/run_validation.sh sets it and plots from it) and every
// reported number, printed and appended to numbers.txt there.
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <string>

namespace efdem::test {

inline std::filesystem::path validation_out_dir() {
    const char* env = std::getenv("EFDEM_VALIDATION_OUT");
    std::filesystem::path dir = env ? env : "validation_out";
    std::filesystem::create_directories(dir);
    return dir;
}

inline void validation_report(const std::string& line) {
    std::printf("validation: %s\n", line.c_str());
    if (std::FILE* f = std::fopen((validation_out_dir() / "numbers.txt").string().c_str(), "a")) {
        std::fprintf(f, "%s\n", line.c_str());
        std::fclose(f);
    }
}

}  // namespace efdem::test
