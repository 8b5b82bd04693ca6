/* placeholder until the solve tests land */
static const rad_test_case tests_solve[] = { { NULL, NULL } };
