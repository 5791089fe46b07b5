# Camera tracking tests. *Parity* cases compare CPU and CUDA (ctest label gpu).
seamless_test(test_tracker_icp SOURCES tracker_icp_test.cpp LIBS seamless_tracker seamless_eval)
seamless_test(test_tracker_sequence SOURCES tracker_sequence_test.cpp LIBS seamless_tracker seamless_refine seamless_eval)
seamless_test(test_tracker_parity SOURCES tracker_parity_test.cpp LIBS seamless_tracker seamless_eval)
# External trackers (src/recon/external/): OpenCV / PCL cases skip when the module is off.
seamless_test(test_tracker_external SOURCES external_tracker_test.cpp LIBS seamless_tracker seamless_eval)
# Dynamic pixels, ghosts and tracking with a person walking through (Parity: label gpu).
seamless_test(test_dynamic SOURCES dynamic_test.cpp LIBS seamless_tracker seamless_eval)
seamless_test(test_dynamic_kernels SOURCES dynamic_kernels_test.cpp LIBS seamless_tracker seamless_eval)
# The dynamic mask against the movers' ground truth (recon/mask_score; summary.json dynamic.mask).
seamless_test(test_mask_score SOURCES mask_score_test.cpp LIBS seamless_tracker)
