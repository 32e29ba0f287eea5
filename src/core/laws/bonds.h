/* The bond-law registry. Adding a bond kind: its header under laws/ (see
 * bond.h and docs/developer.md), included here, and its name appended to
 * SX_BONDS. The order lists them (m:bond's kinds, the union of their
 * micro-parameters: the files' bond_* columns): append only. */
#pragma once

#include "contact_bond.h"
#include "flatjoint.h"
#include "parallel_bond.h"

#define SX_BONDS(X) X(parallel_bond) X(contact_bond) X(flatjoint)
