#pragma once
// Fixture: core reaching into server/.
#include "jobs/design_job.hpp"
#include "fem/element.hpp"
