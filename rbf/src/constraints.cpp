#include "vitri/rbf/constraints.hpp"
