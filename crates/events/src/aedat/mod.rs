//! AEDAT 4.0 (iniVation DV) files and network streams: reader and writer.
