#pragma once
// Fixture: fem reaching up into solve.
#include "solve/solver.hpp"
