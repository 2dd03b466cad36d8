// Status plumbing, on the model of abseil's internal status_macros.h:
//
//   RETURN_IF_ERROR(WriteFile(path));        // returns the status unless it is OK
//   ASSIGN_OR_RETURN(Mesh mesh, ReadMesh(p)); // declares `mesh` from a StatusOr, or returns
//
// Both work in functions that return absl::Status or absl::StatusOr<T> (a
// Status converts to either). The expression is evaluated once.
// ASSIGN_OR_RETURN expands to several statements (its declaration must
// outlive it), so under an `if` or `else` it takes braces.
#pragma once

#include <utility>

#include "absl/status/status.h"
#include "absl/status/statusor.h"

#define SURFINSPECT_STATUS_CONCAT_INNER(a, b) a##b
#define SURFINSPECT_STATUS_CONCAT(a, b) SURFINSPECT_STATUS_CONCAT_INNER(a, b)

// Returns the status of `expr` (an absl::Status) from the enclosing function
// unless it is OK.
#define RETURN_IF_ERROR(expr)                                                          \
  do {                                                                                 \
    ::absl::Status surfinspect_status_macro_status = (expr);                           \
    if (!surfinspect_status_macro_status.ok()) return surfinspect_status_macro_status; \
  } while (false)

// `expr` is an absl::StatusOr<T>: on error its status is returned from the
// enclosing function; otherwise its value is moved into `lhs` (a declaration
// such as `auto x` or `Mesh mesh`, or an existing variable).
#define ASSIGN_OR_RETURN(lhs, expr)                                                             \
  SURFINSPECT_ASSIGN_OR_RETURN_IMPL(SURFINSPECT_STATUS_CONCAT(surfinspect_statusor_, __LINE__), \
                                    lhs, expr)

#define SURFINSPECT_ASSIGN_OR_RETURN_IMPL(statusor, lhs, expr) \
  auto statusor = (expr);                                      \
  if (!statusor.ok()) return std::move(statusor).status();     \
  lhs = *std::move(statusor)
