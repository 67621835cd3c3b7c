//! The pipeline's first step: filters that clean a sensor cloud before queries
//! (self-filter, shadow/veil filter, crop box, voxel downsampling, statistical
//! outlier removal). To be written.
