#include <iostream>

#include "drt/cli.h"
#include "drt/interrupt.h"

int main(int argc, char** argv) {
    drt::install_interrupt_handlers();
    return drt::run_cli(argc, argv, std::cout, std::cerr);
}
