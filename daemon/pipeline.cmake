# The per-sample pipeline of gyrod (pure wiring of processing/; no I/O).
add_library(gyrod_daemon_pipeline STATIC ${CMAKE_CURRENT_SOURCE_DIR}/sample_pipeline.cpp)
target_include_directories(gyrod_daemon_pipeline PUBLIC ${PROJECT_SOURCE_DIR})
target_link_libraries(gyrod_daemon_pipeline PUBLIC gyrod_motion gyrod_attitude gyrod_formats)
