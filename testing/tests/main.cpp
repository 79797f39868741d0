// Catch2's main for test_testing (the library's own tests share tests/catch_main.cpp).
#define CATCH_CONFIG_MAIN
#include <catch2/catch.hpp>
