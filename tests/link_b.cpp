// link_b.cpp - C++ code using the declarations only; linked with the C implementation unit.
#include "../radiosity.h"
#include <cstring>
extern "C" int link_b_result_is_named(void)
{
    return std::strstr(rad_result_string(RAD_ERROR_EMPTY_SCENE), "EMPTY_SCENE") != nullptr;
}
