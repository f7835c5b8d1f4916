// Build-time switches of the ECS: the assert used for programmer mistakes (stale handles, missing
// components). Asserts are on when NDEBUG is not defined, or when ENGINE_ECS_ENABLE_ASSERTS is defined (tests
// do this).
#pragma once

#include <cstdio>
#include <cstdlib>

#if !defined(NDEBUG) || defined(ENGINE_ECS_ENABLE_ASSERTS)
#define ENGINE_ECS_ASSERTS_ON 1
// Prints "engine::ecs: <message> (<condition>) at file:line" to stderr and aborts.
#define ENGINE_ECS_ASSERT(cond, msg)                                                                 \
    do {                                                                                             \
        if (!(cond)) {                                                                               \
            std::fprintf(stderr, "engine::ecs: %s (%s) at %s:%d\n", msg, #cond, __FILE__, __LINE__); \
            std::abort();                                                                            \
        }                                                                                            \
    } while (false)
#else
#define ENGINE_ECS_ASSERTS_ON 0
#define ENGINE_ECS_ASSERT(cond, msg) ((void)0)
#endif
