#pragma once
/// \file
/// The composition site of the contact laws (contact/law.cuh): a new law is one header and
/// one line here.
#include "capillary.cuh"
#include "hertz_mindlin.cuh"
#include "linear.cuh"
#include "materials.cuh"
#include "rolling.cuh"
