#include <iostream>

#include "drt/cli.h"

int main(int argc, char** argv) {
    return drt::run_cli(argc, argv, std::cout, std::cerr);
}
