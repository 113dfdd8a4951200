// Test library (brain_loader_test): a shared library that is no brain library (no SWARMBOX_BRAIN,
// not linked with swarmbox::brain).
extern "C" int swarmbox_test_not_a_brain() { return 42; }
