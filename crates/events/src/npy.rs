//! NPY event files (structured `t,x,y,p`).
