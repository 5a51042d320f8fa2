//! CSV event files (`t,x,y,p`) and IMU CSV files.
