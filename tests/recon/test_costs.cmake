# Rough seconds on 2 cores of the longest discovered cases, for ctest -j's order in a clean build
# (tests/app/CMakeLists.txt says why). Included by ctest after the cases are discovered.
set_tests_properties(
  TrackSequence.TumFreiburg1RpyBestTrackerTracksEveryFrameAndRefinesWithinThreeCentimetres PROPERTIES COST 110)
set_tests_properties(TrackSequence.SyntheticRoomFrameToModelWithinOneCentimetre PROPERTIES COST 45)
set_tests_properties(TrackSequence.CutIsDetectedNotFusedAndTrackingResumes PROPERTIES COST 35)
