#include "app/cli/Commands.h"

int main(int argc, char** argv) {
    return subscan::cli::run(argc, argv);
}
