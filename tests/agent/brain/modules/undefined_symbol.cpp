// Test library (brain_loader_test): calls a function nothing defines; dlopen with RTLD_NOW must
// refuse it at load time (dlerror names the symbol), not crash at the first call.
extern "C" int swarmbox_test_never_defined();
extern "C" int swarmbox_test_calls_undefined() { return swarmbox_test_never_defined(); }
