#define RADIOSITY_IMPLEMENTATION
#include "radiosity.h"
